# Runs a command that must fail cleanly: exit status 1 (the CLI's error exit, not a signal) and
# stderr matching EXPECT. Optionally writes WRITE_FILE with WRITE_CONTENT first (crafted input).
#   cmake -DCMD="a;b;c" -DEXPECT=regex [-DWRITE_FILE=path -DWRITE_CONTENT=text] -P ExpectCliError.cmake
if(DEFINED WRITE_FILE)
  file(WRITE "${WRITE_FILE}" "${WRITE_CONTENT}")
endif()
execute_process(COMMAND ${CMD} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
if(NOT rc STREQUAL "1")
  message(FATAL_ERROR "expected exit status 1, got '${rc}'\nstdout: ${out}\nstderr: ${err}")
endif()
if(NOT err MATCHES "${EXPECT}")
  message(FATAL_ERROR "stderr does not match '${EXPECT}':\n${err}")
endif()
message(STATUS "ok: ${err}")
