# tetseg_add_asset(<target> OUTPUT <asset> SOURCE <mesh> [OPTIONS <tetseg build options>...])
#
# Adds a custom target that builds one asset with `tetseg build`, re-run only when the source
# mesh, the options or the tool change. Several assets build in parallel under Ninja.
# TETSEG_EXECUTABLE names the tool (defaults to the in-tree `tetseg` target).
function(tetseg_add_asset target)
  cmake_parse_arguments(ARG "" "OUTPUT;SOURCE" "OPTIONS" ${ARGN})
  if(NOT ARG_OUTPUT OR NOT ARG_SOURCE)
    message(FATAL_ERROR "tetseg_add_asset(${target}): OUTPUT and SOURCE are required")
  endif()
  if(TETSEG_EXECUTABLE)
    set(tool ${TETSEG_EXECUTABLE})
    set(tool_dependency ${TETSEG_EXECUTABLE})
  else()
    set(tool $<TARGET_FILE:tetseg>)
    set(tool_dependency tetseg)
  endif()
  get_filename_component(source ${ARG_SOURCE} ABSOLUTE)
  set(inputs ${source})
  # TetGen meshes come as a .node/.ele pair.
  if(source MATCHES "\\.(node|ele)$")
    string(REGEX REPLACE "\\.(node|ele)$" "" stem ${source})
    set(inputs ${stem}.node ${stem}.ele)
  endif()
  add_custom_command(
    OUTPUT ${ARG_OUTPUT}
    COMMAND ${tool} build ${source} -o ${ARG_OUTPUT} --quiet ${ARG_OPTIONS}
    DEPENDS ${inputs} ${tool_dependency}
    COMMENT "tetseg build ${ARG_SOURCE}"
    VERBATIM)
  add_custom_target(${target} ALL DEPENDS ${ARG_OUTPUT})
endfunction()
