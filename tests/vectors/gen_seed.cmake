# `cbvh vectors gen --seed S` takes S as decimal (leading zeros included: it
# was read as octal) or as hex after 0x/0X, and writes it to the header.
set(dir ${WORK}/gen_seed)
foreach(case "010|0x000000000000000A" "18446744073709551615|0xFFFFFFFFFFFFFFFF" "0x1f|0x000000000000001F"
             "0XCB7C0DE5EED00001|0xCB7C0DE5EED00001")
    string(REPLACE "|" ";" parts "${case}")
    list(GET parts 0 seed)
    list(GET parts 1 want)
    file(REMOVE_RECURSE ${dir})
    execute_process(COMMAND ${CBVH} vectors gen -u ray_box -s ${seed} -o ${dir}
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "--seed ${seed}: exit ${rc}: ${out}${err}")
    endif()
    file(STRINGS ${dir}/ray_box-N6-ms-30.vec got REGEX "^seed: ")
    if(NOT got STREQUAL "seed: ${want}")
        message(FATAL_ERROR "--seed ${seed}: header says '${got}', want 'seed: ${want}'")
    endif()
endforeach()
file(REMOVE_RECURSE ${dir})
message(STATUS "decimal and hex seeds read as written")
