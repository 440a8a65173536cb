# Runs one command and checks its exit code and output.
# -DCOMMAND="a|b|c" -DEXPECT_CODE=N [-DEXPECT_OUT=regex] [-DEXPECT_ERR=regex] [-DEXPECT_REJECT=regex]
# [-DEXPECT_NO_FILE=path] [-DEXPECT_FILE=path [-DEXPECT_FILE_MATCH=regex] [-DEXPECT_FILE_REJECT=regex]]
# (EXPECT_REJECT: a regex stdout must not match.)

# Fails when `text` does not match the regex held by the variable named `match` (if it is
# defined), or matches the one held by the variable named `reject` (if defined). `what` names
# the text in the message, followed by `shown`.
function(expect_text what text shown match reject)
  if(DEFINED ${match} AND NOT text MATCHES "${${match}}")
    message(FATAL_ERROR "${what} does not match '${${match}}'${shown}")
  endif()
  if(DEFINED ${reject} AND text MATCHES "${${reject}}")
    message(FATAL_ERROR "${what} matches '${${reject}}'${shown}")
  endif()
endfunction()

string(REPLACE "|" ";" COMMAND "${COMMAND}")
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE code OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT "${code}" STREQUAL "${EXPECT_CODE}")
  message(FATAL_ERROR "exit code ${code}, expected ${EXPECT_CODE}\nstdout:\n${out}\nstderr:\n${err}")
endif()
expect_text(stdout "${out}" ":\n${out}" EXPECT_OUT EXPECT_REJECT)
expect_text(stderr "${err}" ":\n${err}" EXPECT_ERR EXPECT_ERR_REJECT)  # (no stderr reject)
if(DEFINED EXPECT_NO_FILE AND EXISTS "${EXPECT_NO_FILE}")
  message(FATAL_ERROR "${EXPECT_NO_FILE} was written")
endif()
if(DEFINED EXPECT_FILE)
  if(NOT EXISTS "${EXPECT_FILE}")
    message(FATAL_ERROR "${EXPECT_FILE} was not written")
  endif()
  if(DEFINED EXPECT_FILE_MATCH OR DEFINED EXPECT_FILE_REJECT)
    file(READ "${EXPECT_FILE}" content)
    expect_text("${EXPECT_FILE}" "${content}" "" EXPECT_FILE_MATCH EXPECT_FILE_REJECT)
  endif()
endif()
