#pragma once
#include "pmu/dispatch/command_service.hpp"
