# cmake -DCBVH=... -DSCENE=... -DOUT=... -P undefined_ratio.cmake
# A scene whose primary rays all miss: neither BVH does a triangle test or
# fetches a byte, so those ratios are 0/0.  The table prints "-" (not 1.000),
# the JSON null (not 1), and the knee is not computed from them.
file(REMOVE_RECURSE "${OUT}")
execute_process(COMMAND "${CBVH}" sweep "${SCENE}" --bits 5..6 --out "${OUT}"
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "exit ${rc}: ${err}")
endif()
foreach(re "N=6 M=24 E=-30 +total +48 [^|\n]*\\| +1\\.000 +- +- +0\\.[0-9]+ +1\\.000 +[0-9.]+ +same\n"
        "M=24 E=-30: box tests N=5, triangle tests -, bytes -, modelled time N=5\n"
        "\\(-: the float BVH did none of it, so there is no ratio and no knee\\)\n"
        "here \\(M=24 E=-30\\): box tests x1\\.000, triangle tests -\n")
    if(NOT out MATCHES "${re}")
        message(FATAL_ERROR "table does not match '${re}':\n${out}")
    endif()
endforeach()
if(out MATCHES "nan")
    message(FATAL_ERROR "a NaN in the table:\n${out}")
endif()
# The chart draws only the costs that have a ratio.
file(READ "${OUT}/cost.svg" svg)
string(REGEX MATCHALL "<polyline" lines "${svg}")
list(LENGTH lines nl)
if(NOT nl EQUAL 2)
    message(FATAL_ERROR "cost.svg: ${nl} series, expected 2 (box tests, modelled time)")
endif()
execute_process(COMMAND "${CBVH}" sweep "${SCENE}" --bits 5..6 --out "${OUT}" --json
    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "--json: exit ${rc}: ${err}")
endif()
foreach(path "settings;1;total;relative_to_float;tri_tests" "settings;1;total;relative_to_float;bytes"
        "float;total;relative_to_float;tri_tests" "knee;0;tri_tests" "knee;0;bytes")
    string(JSON t TYPE "${out}" ${path})
    if(NOT t STREQUAL "NULL")
        string(JSON v GET "${out}" ${path})
        message(FATAL_ERROR "--json ${path}: ${t} ${v}, expected null")
    endif()
endforeach()
string(JSON v GET "${out}" settings 1 total relative_to_float box_tests)
string(JSON k GET "${out}" knee 0 box_tests)
if(NOT v EQUAL 1 OR NOT k EQUAL 5)
    message(FATAL_ERROR "--json: box_tests ratio ${v} (expected 1), knee ${k} (expected 5)")
endif()
message(STATUS "ok: 0/0 is '-' and null, and no knee")
