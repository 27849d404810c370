# `cbvh vectors gen` whose only file cannot be written (its name is taken by a
# directory) exits 2 naming the file and leaves no MANIFEST behind: a later
# check must not find an empty manifest vouching for nothing.
set(dir ${WORK}/gen_failed_write)
file(REMOVE_RECURSE ${dir})
file(MAKE_DIRECTORY ${dir}/ray_box-N6-ms-30.vec/occupied)
execute_process(COMMAND ${CBVH} vectors gen -u ray_box -o ${dir}
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 2)
    message(FATAL_ERROR "expected exit 2, got ${rc}: ${out}${err}")
endif()
if(NOT err MATCHES "^cbvh vectors gen: [^\n]*ray_box-N6-ms-30.vec: cannot write[^\n]*\n$")
    message(FATAL_ERROR "expected one line naming the file, got: ${err}")
endif()
if(EXISTS ${dir}/MANIFEST)
    message(FATAL_ERROR "a MANIFEST was left behind after the failed write")
endif()
file(GLOB left ${dir}/.*)
if(left)
    message(FATAL_ERROR "temporary files left behind: ${left}")
endif()
file(REMOVE_RECURSE ${dir})
