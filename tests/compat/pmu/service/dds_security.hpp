#pragma once
#include "pmu/security/security_files.hpp"
