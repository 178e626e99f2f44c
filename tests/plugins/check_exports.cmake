# ctest script: each plugin library exports exactly one symbol, mneedle_plugin_entry.
# Arguments: -DNM=<nm> -DPLUGINS=<file;file;...>
foreach(plugin IN LISTS PLUGINS)
  execute_process(COMMAND ${NM} -D --defined-only ${plugin}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${plugin}: nm failed: ${err}")
  endif()
  string(REGEX MATCHALL "[^\n]+" symbols "${out}")
  list(LENGTH symbols count)
  if(NOT count EQUAL 1 OR NOT out MATCHES " T mneedle_plugin_entry\n")
    message(FATAL_ERROR "${plugin} must export only mneedle_plugin_entry, exports:\n${out}")
  endif()
endforeach()
