#pragma once
#include "pmu/config/config.hpp"
