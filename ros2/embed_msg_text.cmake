# cmake -DOUT=file.hpp -DMSG_DIR=dir "-DTYPES=sensor_msgs/BatteryState;..." -P embed_msg_text.cmake
# Writes a header with each message's definition as the `ros2msg` schema of MCAP and Foxglove
# channels (pmuctl record / serve): the message's text, then per dependency a line of 80 '='
# and `MSG: pkg/Name` with its text. @foxglove/rosmsg-msgs-common's msgdefs carry each .msg in
# that shape already, so the file is taken as it is.
set(body "#pragma once\n// Generated from @foxglove/rosmsg-msgs-common's msgdefs by ros2/embed_msg_text.cmake at build time; not committed.\n#include <string_view>\n\nnamespace pmu::ros2_msg_text {\n\n")
foreach(type ${TYPES})
  string(REPLACE "/" "/msg/" path ${type})
  get_filename_component(name ${type} NAME)
  set(file ${MSG_DIR}/${path}.msg)
  file(READ ${file} text)
  if(text MATCHES "\\)rosmsg\"")
    message(FATAL_ERROR "${file} contains the raw-string delimiter )rosmsg\"")
  endif()
  string(APPEND body "inline constexpr std::string_view k_${name} = R\"rosmsg(${text})rosmsg\";\n\n")
endforeach()
string(APPEND body "}  // namespace pmu::ros2_msg_text\n")
file(WRITE ${OUT}.tmp "${body}")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
file(REMOVE ${OUT}.tmp)
