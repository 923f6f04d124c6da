#pragma once
#include "pmu/dds/dds_context.hpp"
