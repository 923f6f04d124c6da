#pragma once
#include "pmu/command/command.hpp"
