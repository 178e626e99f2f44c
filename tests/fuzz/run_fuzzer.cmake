# Runs one libFuzzer harness repeatably: a fresh output corpus (libFuzzer writes new inputs into
# the first folder it is given, so the repository's seed folders are never written), the seeds
# after it, a fixed seed and number of inputs. A crash leaves its input in WORK/crash-*: add it
# to the harness's corpus as a regression case once fixed.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK}/corpus)
execute_process(
  COMMAND ${CMAKE_COMMAND} -E env LSAN_OPTIONS=suppressions=${CMAKE_CURRENT_LIST_DIR}/lsan.supp
          ${FUZZER} -runs=${RUNS} -seed=1 -max_len=${MAX_LEN} -timeout=10 -rss_limit_mb=2048
          -print_final_stats=1 -artifact_prefix=${WORK}/ ${WORK}/corpus ${CORPUS}
  WORKING_DIRECTORY ${WORK}
  RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${FUZZER}: exit ${rc}; the input that failed is in ${WORK}/")
endif()
