#pragma once
#include "pmu/dds/dds_publisher.hpp"
