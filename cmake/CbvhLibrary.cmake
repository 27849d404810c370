# libcbvh as installed: one library of the whole model, static (libcbvh.a) and
# shared (libcbvh.so.<SOVERSION>), with its public headers, a pkg-config file
# (cbvh.pc) and a CMake package (find_package(cbvh): cbvh::cbvh, cbvh::cbvh_static).
#
# cbvh_library_package() is called at the end of rtl-model/ (cmake_language(DEFER)
# in rtl-model/CMakeLists.txt).  It takes every static library defined there —
# the units (cbvh_model), build, traverse, qbvh, tlist, and any library added
# there later — and links their object files, as compiled for the tool and the
# tests (position-independent, with their per-file -O3, -ffp-contract=off and
# -mavx), into both libcbvh.a and libcbvh.so: the installed library is the code
# the tests ran.  The host tool's libraries (host/: assimp, libusb, ...) are not
# part of it: a testbench needs the model, not the board link or the importers.

include(CMakePackageConfigHelpers)

# While the major version is 0 every minor version may change the ABI: the
# soname and the package's compatibility carry major.minor (libcbvh.so.0.1).
if(PROJECT_VERSION_MAJOR EQUAL 0)
    set(CBVH_SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
    set(CBVH_VERSION_COMPAT SameMinorVersion)
else()
    set(CBVH_SOVERSION ${PROJECT_VERSION_MAJOR})
    set(CBVH_VERSION_COMPAT SameMajorVersion)
endif()

set(CBVH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/cbvh)

function(cbvh_library_package)
    get_property(targets DIRECTORY PROPERTY BUILDSYSTEM_TARGETS)
    set(parts "")
    foreach(t IN LISTS targets)
        get_target_property(type ${t} TYPE)
        if(type STREQUAL "STATIC_LIBRARY")
            list(APPEND parts ${t})
        endif()
    endforeach()
    # What the parts link outside themselves becomes libcbvh's own dependency
    # (Libs.private, the static target's INTERFACE_LINK_LIBRARIES).  Plain
    # system libraries only: anything else needs a find_dependency in
    # cmake/cbvhConfig.cmake.in and a Requires.private in cmake/cbvh.pc.in.
    set(objects "")
    set(deps "")
    foreach(p IN LISTS parts)
        get_target_property(pic ${p} POSITION_INDEPENDENT_CODE)
        if(NOT pic)
            message(FATAL_ERROR "libcbvh: ${p} is not position-independent (set it before add_library in rtl-model/)")
        endif()
        list(APPEND objects $<TARGET_OBJECTS:${p}>)
        get_target_property(libs ${p} LINK_LIBRARIES)
        foreach(l IN LISTS libs)
            if(l IN_LIST parts)
                continue()
            elseif(NOT l MATCHES "^[A-Za-z0-9_]+$" OR TARGET ${l})
                message(FATAL_ERROR "libcbvh: ${p} links ${l}; only system libraries (-lNAME) are handled "
                                    "(cmake/CbvhLibrary.cmake)")
            endif()
            list(APPEND deps ${l})
        endforeach()
    endforeach()
    list(REMOVE_DUPLICATES deps)
    string(JOIN " " msg ${parts})
    message(STATUS "libcbvh (static and shared): ${msg}; links ${deps}")

    set(include_dirs $<BUILD_INTERFACE:${CBVH_MODEL_INCLUDE}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    add_library(cbvh_shared SHARED ${objects})
    target_link_libraries(cbvh_shared PRIVATE ${deps})
    set_target_properties(cbvh_shared PROPERTIES VERSION ${PROJECT_VERSION} SOVERSION ${CBVH_SOVERSION})
    add_library(cbvh_static STATIC ${objects})
    target_link_libraries(cbvh_static INTERFACE ${deps})
    foreach(t cbvh_shared cbvh_static)
        string(REPLACE "cbvh_shared" "cbvh" export_name ${t})
        set_target_properties(${t} PROPERTIES OUTPUT_NAME cbvh EXPORT_NAME ${export_name} LINKER_LANGUAGE C)
        target_include_directories(${t} INTERFACE ${include_dirs})
        add_library(cbvh::${export_name} ALIAS ${t})
    endforeach()

    install(TARGETS cbvh_shared cbvh_static EXPORT cbvhTargets
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
    install(DIRECTORY ${CBVH_MODEL_INCLUDE}/cbvh DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.h")

    # CMake package: relocatable (paths relative to the installed config file).
    install(EXPORT cbvhTargets NAMESPACE cbvh:: DESTINATION ${CBVH_INSTALL_CMAKEDIR})
    set(dir ${PROJECT_BINARY_DIR}/cmake)
    configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/cbvhConfig.cmake.in ${dir}/cbvhConfig.cmake
        INSTALL_DESTINATION ${CBVH_INSTALL_CMAKEDIR} PATH_VARS CBVH_INSTALL_VECTORSDIR CMAKE_INSTALL_BINDIR)
    write_basic_package_version_file(${dir}/cbvhConfigVersion.cmake COMPATIBILITY ${CBVH_VERSION_COMPAT})
    install(FILES ${dir}/cbvhConfig.cmake ${dir}/cbvhConfigVersion.cmake DESTINATION ${CBVH_INSTALL_CMAKEDIR})

    # pkg-config: relocatable too, the prefix found from the .pc file's own
    # place (${pcfiledir}) when the install directories are relative to it.
    set(pcdir ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
    if(IS_ABSOLUTE "${pcdir}")
        set(CBVH_PC_PREFIX "${CMAKE_INSTALL_PREFIX}")
    else()
        file(RELATIVE_PATH rel /prefix/${pcdir} /prefix)
        string(REGEX REPLACE "/$" "" rel "${rel}")
        set(CBVH_PC_PREFIX "\${pcfiledir}/${rel}")
    endif()
    foreach(v LIBDIR INCLUDEDIR VECTORSDIR)
        if(v STREQUAL "VECTORSDIR")
            set(d ${CBVH_INSTALL_VECTORSDIR})
        else()
            set(d ${CMAKE_INSTALL_${v}})
        endif()
        if(IS_ABSOLUTE "${d}")
            set(CBVH_PC_${v} "${d}")
        else()
            set(CBVH_PC_${v} "\${prefix}/${d}")
        endif()
    endforeach()
    list(TRANSFORM deps PREPEND "-l" OUTPUT_VARIABLE CBVH_PC_LIBS_PRIVATE)
    string(JOIN " " CBVH_PC_LIBS_PRIVATE ${CBVH_PC_LIBS_PRIVATE})
    configure_file(${PROJECT_SOURCE_DIR}/cmake/cbvh.pc.in ${dir}/cbvh.pc @ONLY)
    install(FILES ${dir}/cbvh.pc DESTINATION ${pcdir})
endfunction()
