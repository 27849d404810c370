# Results written to a full disk must not pass as success: with stdout on
# /dev/full every command exits non-zero with one line saying so.
if(NOT EXISTS /dev/full)
    message("no /dev/full here: nothing to check")
    return()
endif()
separate_arguments(args UNIX_COMMAND "${ARGS}")
execute_process(COMMAND ${CBVH} ${args} WORKING_DIRECTORY ${SRC}
    RESULT_VARIABLE rc OUTPUT_FILE /dev/full ERROR_VARIABLE err)
if(rc EQUAL 0)
    message(FATAL_ERROR "cbvh ${ARGS} > /dev/full exited 0: ${err}")
endif()
if(NOT err MATCHES "cbvh: cannot write the output to standard output: [^\n]*\n$")
    message(FATAL_ERROR "expected one last line about the lost output, got: ${err}")
endif()
