# ctest labels `full` and `quick`.
#
#   full   every test (the README's `cmake --workflow --preset default`, CI).
#   quick  every test except those whose names match CBVH_FULL_ONLY_TESTS (the
#          top-level CMakeLists.txt: the one list of what quick leaves out, and
#          why); `ctest --preset quick`, under about 3 minutes on 2 cores.
#
# Every folder that adds tests calls cbvh_label_tests() once (its first line):
# at the end of the folder (cmake_language(DEFER)) it labels every test the
# folder added, wherever in the file, so a new test needs no extra work.  The
# configure fails when a folder with tests does not call it, or when an entry
# of CBVH_FULL_ONLY_TESTS matches no test (a renamed slow test would otherwise
# join quick without a word).
#
# Why per folder: CMake 3.25 sets a test's properties only from the test's own
# folder, and ctest ignores the directory property LABELS for tests that have
# a WORKING_DIRECTORY.

function(cbvh_label_tests)
    set_property(GLOBAL APPEND PROPERTY CBVH_LABELLED_DIRS ${CMAKE_CURRENT_SOURCE_DIR})
    cmake_language(DEFER CALL _cbvh_label_tests_here)
endfunction()

function(_cbvh_label_tests_here)
    get_property(tests DIRECTORY PROPERTY TESTS)
    foreach(t IN LISTS tests)
        set(labels full quick)
        foreach(re IN LISTS CBVH_FULL_ONLY_TESTS)
            if(t MATCHES "${re}")
                set(labels full)
                set_property(GLOBAL APPEND PROPERTY CBVH_FULL_ONLY_USED "${re}")
            endif()
        endforeach()
        set_property(TEST ${t} APPEND PROPERTY LABELS ${labels})
    endforeach()
endfunction()

# Called once, in the top-level CMakeLists.txt: checks the whole tree at its end.
function(cbvh_check_test_labels)
    cmake_language(DEFER CALL _cbvh_check_test_labels)
endfunction()

function(_cbvh_check_test_labels)
    get_property(labelled GLOBAL PROPERTY CBVH_LABELLED_DIRS)
    set(queue ${PROJECT_SOURCE_DIR})
    set(unlabelled "")
    while(queue)
        list(POP_FRONT queue dir)
        get_property(subdirs DIRECTORY ${dir} PROPERTY SUBDIRECTORIES)
        list(APPEND queue ${subdirs})
        get_property(tests DIRECTORY ${dir} PROPERTY TESTS)
        if(tests AND NOT dir IN_LIST labelled)
            list(APPEND unlabelled ${dir})
        endif()
    endwhile()
    if(unlabelled)
        message(FATAL_ERROR "ctest labels: ${unlabelled} adds tests but does not call cbvh_label_tests() "
                            "(cmake/CbvhTestLabels.cmake)")
    endif()
    get_property(used GLOBAL PROPERTY CBVH_FULL_ONLY_USED)
    foreach(re IN LISTS CBVH_FULL_ONLY_TESTS)
        if(NOT re IN_LIST used)
            message(FATAL_ERROR "ctest labels: CBVH_FULL_ONLY_TESTS entry '${re}' matches no test")
        endif()
    endforeach()
endfunction()
