# pmu_warnings: an interface target every first-party target links, so all of our code is
# compiled with the same warnings while generated and third-party code is not.
add_library(pmu_warnings INTERFACE)
target_compile_options(pmu_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow
  -Wnon-virtual-dtor -Wold-style-cast -Wcast-align -Woverloaded-virtual
  -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough -Wswitch-enum)
if(PMU_WERROR)
  target_compile_options(pmu_warnings INTERFACE -Werror)
endif()
add_library(pmu::warnings ALIAS pmu_warnings)
