# cmake -DCBVH=... -DSCENE=... -DOUT=... -P json_file_not_written.cmake
# An output file that cannot be written (here cost.svg is a directory, so
# renaming the finished chart onto it fails, as root too): with --json there is
# no JSON on stdout (its "files" would read as a complete run), one line on
# stderr, exit 2; without --json the table, then the same one line.
file(REMOVE_RECURSE "${OUT}")
file(MAKE_DIRECTORY "${OUT}/cost.svg")
foreach(mode json text)
    set(args sweep "${SCENE}" --bits 6 --out "${OUT}")
    if(mode STREQUAL "json")
        list(APPEND args --json)
    endif()
    execute_process(COMMAND "${CBVH}" ${args} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 2)
        message(FATAL_ERROR "${mode}: exit ${rc}, expected 2:\n${out}${err}")
    endif()
    if(NOT err MATCHES "^cbvh sweep: svg: cannot rename [^\n]*/cost\\.svg\\.tmp\\.[^\n]* to [^\n]*/cost\\.svg: [^\n]+\n$")
        message(FATAL_ERROR "${mode}: expected one line about cost.svg, got:\n${err}")
    endif()
    if(mode STREQUAL "json" AND NOT out STREQUAL "")
        message(FATAL_ERROR "JSON printed although a file was not written:\n${out}")
    endif()
    if(mode STREQUAL "text" AND (NOT out MATCHES "wrote [^\n]*/render-float\\.png\n" OR out MATCHES "cost\\.svg"))
        message(FATAL_ERROR "text: expected the table listing only the files written:\n${out}")
    endif()
endforeach()
message(STATUS "ok: no JSON, one line, exit 2")
