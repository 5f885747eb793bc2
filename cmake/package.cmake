# The CMake package (find_package(glint)) and the Debian packages (make package):
#   glint_<version>_amd64.deb      bin/glint, the plugins, the models, the Python module
#   glint-dev_<version>_amd64.deb  headers, static libraries, the CMake package files
include(CMakePackageConfigHelpers)

install(EXPORT glintTargets NAMESPACE glint:: DESTINATION ${GLINT_INSTALL_CMAKEDIR}
        COMPONENT development)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/glintConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/glintConfig.cmake
                              INSTALL_DESTINATION ${GLINT_INSTALL_CMAKEDIR}
                              PATH_VARS GLINT_INSTALL_MODELSDIR)
# 0.x: a minor version may change the API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/glintConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/glintConfig.cmake ${PROJECT_BINARY_DIR}/glintConfigVersion.cmake
        DESTINATION ${GLINT_INSTALL_CMAKEDIR} COMPONENT development)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME glint)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "glint developers <glint@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "practical real-time reflectance estimation: edges, denoising, reflectance")
set(CPACK_PACKAGE_DESCRIPTION
    "glint detects sharp edges and boundaries in point clouds (BoundED), denoises images with "
    "locally-guided Deep Image Prior and Self2Self, and reconstructs geometry, lights and "
    "materials online from RGB-D streams. One command-line tool and a Python module.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime development)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME glint)
set(CPACK_DEBIAN_DEVELOPMENT_PACKAGE_NAME glint-dev)
# The shared libraries the binary, plugins and Python module load (dpkg-shlibdeps), plus what
# the Python module needs at run time.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "python3, python3-numpy")
# libtorch's CPU convolutions call BLAS: OpenBLAS makes the neural denoisers several times faster.
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS "libopenblas0-openmp")
# glintConfig.cmake's find_dependency() calls, and the runtime package for the models.
set(glint_dev_depends
    "glint (= ${PROJECT_VERSION}), libeigen3-dev, libnanoflann-dev, libtbb-dev, nlohmann-json3-dev,"
    " libfmt-dev, libspdlog-dev, libopencv-dev, libpng-dev, libembree-dev, libtinyobjloader-dev,"
    " libmeshoptimizer-dev,"
    " libocct-foundation-dev, libocct-modeling-data-dev, libocct-modeling-algorithms-dev,"
    " libocct-data-exchange-dev, libyaml-cpp-dev")
string(JOIN "" CPACK_DEBIAN_DEVELOPMENT_PACKAGE_DEPENDS ${glint_dev_depends})
include(CPack)
