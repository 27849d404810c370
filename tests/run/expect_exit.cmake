# `cbvh run --scene <missing>` must exit 2 with one line naming the file,
# before the golden-vector check starts (a typo is not reported after a whole
# check on a board).
execute_process(COMMAND ${CBVH} run --backend model --scene /nonexistent/x.scene
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2)
    message(FATAL_ERROR "expected exit 2, got ${rc}: ${err}")
endif()
if(NOT err MATCHES "^cbvh run: [^\n]*/nonexistent/x.scene[^\n]*\n$")
    message(FATAL_ERROR "expected one line naming the scene file, got: ${err}")
endif()
if(out MATCHES "Golden vectors")
    message(FATAL_ERROR "the vector check ran before the scene was checked: ${out}")
endif()
