#pragma once
#include "pmu/config/vehicle.hpp"
