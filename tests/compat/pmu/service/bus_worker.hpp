#pragma once
#include "pmu/session/bus_worker.hpp"
