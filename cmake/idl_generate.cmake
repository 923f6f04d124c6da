# pmu_idl_generate(): the one place that turns the contract's IDL into code at build time,
# for each IDL compiler the project uses. Nothing generated is committed.
#
#   pmu_idl_generate(<sources-var> COMPILER <compiler> DESTINATION <dir> [INCLUDE <dir>] IDL <file>...)
#
# Appends the generated files to compile to <sources-var> (in the caller's scope); the headers
# land beside them in <dir>. <compiler> is one of
#   fastddsgen             <stem>.h/.cxx and <stem>PubSubTypes.h/.cxx (Fast DDS's types)
#   fastddsgen-typeobject  <stem>TypeObject.h/.cxx only (the XTypes type objects); it compiles
#                          against the <stem>.h of a `fastddsgen` run into the same <dir>
#   idlc                   <stem>.h/.c (Eclipse Cyclone DDS's C types, final extensibility); with
#                          INCLUDE, the root its #includes are found under
#   fastddsgen-ros2        as fastddsgen, for ROS 2 IDL (rosidl's, under INCLUDE as
#                          <pkg>/msg/<Name>.idl): type names as rmw_fastrtps registers them,
#                          <pkg>::msg::dds_::<Name>_
#
# PMU_IDL_FILES: the contract's IDL files (absolute paths), for every caller.
get_filename_component(_pmu_idl_dir "${CMAKE_CURRENT_LIST_DIR}/../idl" ABSOLUTE)
set(PMU_IDL_FILES ${_pmu_idl_dir}/telemetry.idl ${_pmu_idl_dir}/state.idl ${_pmu_idl_dir}/command.idl
                  ${_pmu_idl_dir}/canopen.idl ${_pmu_idl_dir}/alarms.idl ${_pmu_idl_dir}/energy.idl
                  ${_pmu_idl_dir}/role.idl)

function(pmu_idl_generate sources_var)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "COMPILER;DESTINATION;INCLUDE" "IDL")
  if(NOT arg_COMPILER OR NOT arg_DESTINATION OR NOT arg_IDL)
    message(FATAL_ERROR "pmu_idl_generate: COMPILER, DESTINATION and IDL are required")
  endif()
  set(dir ${arg_DESTINATION})
  file(MAKE_DIRECTORY ${dir})
  set(sources ${${sources_var}})
  foreach(idl ${arg_IDL})
    get_filename_component(stem ${idl} NAME_WE)
    if(arg_COMPILER STREQUAL "fastddsgen")
      find_program(FASTDDSGEN fastddsgen REQUIRED)
      # fastddsgen preprocesses the IDL into a file named after it in its temporary folder,
      # /tmp unless -t says otherwise: two runs of the same IDL at once (under ninja -j, or two
      # build trees) would write over each other's copy and generate from a truncated file.
      # Each run gets a folder of its own.
      set(tmp_dir ${CMAKE_CURRENT_BINARY_DIR}/fastddsgen-tmp/${stem})
      add_custom_command(
        OUTPUT ${dir}/${stem}.h ${dir}/${stem}.cxx ${dir}/${stem}PubSubTypes.h ${dir}/${stem}PubSubTypes.cxx
        COMMAND ${CMAKE_COMMAND} -E make_directory ${tmp_dir}
        COMMAND ${FASTDDSGEN} -replace -t ${tmp_dir} -d ${dir} ${idl}
        DEPENDS ${idl}
        COMMENT "fastddsgen ${stem}.idl"
        VERBATIM)
      list(APPEND sources ${dir}/${stem}.cxx ${dir}/${stem}PubSubTypes.cxx)
    elseif(arg_COMPILER STREQUAL "fastddsgen-typeobject")
      find_program(FASTDDSGEN fastddsgen REQUIRED)
      # A second run with -typeobject, in a folder of its own, of which only the two
      # TypeObject files are kept: with -typeobject, fastddsgen 2.3 also makes every type's
      # constructor call register<stem>Types(), which costs ~12 us per sample constructed
      # (against 0.4 us; a linear search of Fast DDS's TypeObjectFactory under its
      # process-wide mutex) on the per-frame path.
      set(to_dir ${CMAKE_CURRENT_BINARY_DIR}/typeobject/${stem})
      add_custom_command(
        OUTPUT ${dir}/${stem}TypeObject.h ${dir}/${stem}TypeObject.cxx
        COMMAND ${CMAKE_COMMAND} -E make_directory ${to_dir}/tmp
        COMMAND ${FASTDDSGEN} -typeobject -replace -t ${to_dir}/tmp -d ${to_dir} ${idl}
        COMMAND ${CMAKE_COMMAND} -E copy ${to_dir}/${stem}TypeObject.h ${to_dir}/${stem}TypeObject.cxx ${dir}
        DEPENDS ${idl}
        COMMENT "fastddsgen -typeobject ${stem}.idl"
        VERBATIM)
      list(APPEND sources ${dir}/${stem}TypeObject.cxx)
    elseif(arg_COMPILER STREQUAL "fastddsgen-ros2")
      find_program(FASTDDSGEN fastddsgen REQUIRED)
      if(NOT arg_INCLUDE)
        message(FATAL_ERROR "pmu_idl_generate: fastddsgen-ros2 needs INCLUDE, the root of the ROS 2 IDL")
      endif()
      # fastddsgen also generates every IDL the file includes, into the same folder: two runs
      # into one package's folder would write the same files at once. Each run has a folder of
      # its own, and only the file's own four are copied out.
      file(RELATIVE_PATH rel ${arg_INCLUDE} ${idl})
      string(REGEX REPLACE "\\.idl$" "" rel ${rel})
      set(run_dir ${CMAKE_CURRENT_BINARY_DIR}/fastddsgen-ros2/${rel})
      set(own ${run_dir}/${stem}.h ${run_dir}/${stem}.cxx ${run_dir}/${stem}PubSubTypes.h ${run_dir}/${stem}PubSubTypes.cxx)
      add_custom_command(
        OUTPUT ${dir}/${stem}.h ${dir}/${stem}.cxx ${dir}/${stem}PubSubTypes.h ${dir}/${stem}PubSubTypes.cxx
        COMMAND ${CMAKE_COMMAND} -E make_directory ${run_dir}/tmp
        COMMAND ${FASTDDSGEN} -typeros2 -replace -t ${run_dir}/tmp -I ${arg_INCLUDE} -d ${run_dir} ${idl}
        COMMAND ${CMAKE_COMMAND} -E copy ${own} ${dir}
        DEPENDS ${idl}
        COMMENT "fastddsgen -typeros2 ${rel}.idl"
        VERBATIM)
      list(APPEND sources ${dir}/${stem}.cxx ${dir}/${stem}PubSubTypes.cxx)
    elseif(arg_COMPILER STREQUAL "idlc")
      find_program(CYCLONE_IDLC idlc PATHS /usr/bin REQUIRED)
      # -x final: fastddsgen 2.3 treats these structs as final (plain CDR, no DHEADER); idlc's
      # default is final today but says it may become appendable, which would not interoperate.
      set(include_args)
      if(arg_INCLUDE)
        set(include_args -I ${arg_INCLUDE})
      endif()
      add_custom_command(
        OUTPUT ${dir}/${stem}.h ${dir}/${stem}.c
        COMMAND ${CYCLONE_IDLC} -l c -x final ${include_args} -o ${dir} ${idl}
        DEPENDS ${idl}
        COMMENT "idlc (Cyclone DDS) ${stem}.idl"
        VERBATIM)
      list(APPEND sources ${dir}/${stem}.c)
    else()
      message(FATAL_ERROR "pmu_idl_generate: unknown COMPILER '${arg_COMPILER}' (fastddsgen, fastddsgen-typeobject, fastddsgen-ros2, idlc)")
    endif()
  endforeach()
  set(${sources_var} ${sources} PARENT_SCOPE)
endfunction()
