#pragma once
#include "pmu/dds/dds_commands.hpp"
