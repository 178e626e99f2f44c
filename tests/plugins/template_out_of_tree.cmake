# ctest script: the plugin author's path end to end. Installs mneedle's plugin_dev component
# into a temporary prefix, builds geometry_plugins/template out of tree against it with
# find_package(mneedle), then loads the result through the CLI (PluginRegistry) and
# generates a validated mesh with it.
# Arguments: -DBUILD_DIR -DTEMPLATE_DIR -DWORK_DIR -DMNEEDLE_EXE
foreach(var BUILD_DIR TEMPLATE_DIR WORK_DIR MNEEDLE_EXE)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "template test: ${var} not set")
  endif()
endforeach()

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "template test: ${step} failed (${rc})\n${out}\n${err}")
  endif()
  set(last_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix} --component plugin_dev)
if(NOT EXISTS ${prefix}/include/mneedle/plugin.h)
  message(FATAL_ERROR "template test: plugin.h was not installed")
endif()
run("configure" ${CMAKE_COMMAND} -S ${TEMPLATE_DIR} -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run("build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run("describe" ${MNEEDLE_EXE} plugins describe pyramid --json --plugin-dir ${WORK_DIR}/build)
if(NOT last_output MATCHES "\"plugin_id\": \"org.example.pyramid\"")
  message(FATAL_ERROR "template test: pyramid not described:\n${last_output}")
endif()
run("generate" ${MNEEDLE_EXE} generate pyramid --plugin-dir ${WORK_DIR}/build
    --set base_width=200um --unit um -o ${WORK_DIR}/pyramid.stl)
if(NOT EXISTS ${WORK_DIR}/pyramid.stl)
  message(FATAL_ERROR "template test: no STL written")
endif()
message(STATUS "template plugin built out of tree and loaded: ${last_output}")
