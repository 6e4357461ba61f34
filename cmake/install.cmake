# Install rules, the CMake package (find_package(rbsim)) and the Debian package (cpack -G DEB).
#
# rbsim's own libraries are static, so the installed `rbsim` needs no RPATH: it depends only on
# Debian's shared libraries (Cyclone DDS, Cairo, zstd, ...), which dpkg-shlibdeps turns into the
# package's Depends. The static libraries and public headers installed beside it are what
# find_package(rbsim) gives a user; their own dependencies are found by rbsimConfig.cmake.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(RBSIM_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/rbsim)

# rbsim::core is the physics and the scene loader together: what a user means by "the simulator".
add_library(rbsim_core_package INTERFACE)
target_link_libraries(rbsim_core_package INTERFACE rbsim_core rbsim_scene)
set(RBSIM_EXPORTED rbsim_core_package rbsim_base rbsim_core rbsim_scene rbsim_mcap rbsim_run rbsim_msgs rbsim_mcap_tools
                   rbsim_recordings rbsim_check rbsim_golden rbsim_control)
set_target_properties(rbsim_core_package PROPERTIES EXPORT_NAME core)
set_target_properties(rbsim_core PROPERTIES EXPORT_NAME physics)
foreach(target rbsim_base rbsim_scene rbsim_mcap rbsim_run rbsim_msgs rbsim_mcap_tools rbsim_recordings rbsim_check rbsim_golden
               rbsim_control)
  string(REPLACE "rbsim_" "" name ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
endforeach()
set(RBSIM_INSTALL_TESTING OFF)
if(TARGET rbsim_testing)
  set(RBSIM_INSTALL_TESTING ON)
  list(APPEND RBSIM_EXPORTED rbsim_testing)
  set_target_properties(rbsim_testing PROPERTIES EXPORT_NAME testing)
endif()

install(TARGETS rbsim RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS ${RBSIM_EXPORTED} EXPORT rbsimTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# The public headers of the exported libraries, and only those (module internals stay in src/).
foreach(dir sim_core/base/include sim_core/include sim_core/scene/include tools/run/include tools/msgs/include tools/mcap/include
            tools/mcap_tools/include tools/recordings/include tools/check/include tools/golden/include tools/control/include)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir}/rbsim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()
if(RBSIM_INSTALL_TESTING)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/tools/testing/include/rbsim DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The Foxglove layout `rbsim node --foxglove` points to (tools/cli/foxglove.cpp looks here first).
install(FILES ${PROJECT_SOURCE_DIR}/docs/foxglove-layout.json DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim)

install(EXPORT rbsimTargets NAMESPACE rbsim:: DESTINATION ${RBSIM_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/rbsimConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/rbsimConfig.cmake INSTALL_DESTINATION ${RBSIM_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/rbsimConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/rbsimConfig.cmake ${PROJECT_BINARY_DIR}/rbsimConfigVersion.cmake
        DESTINATION ${RBSIM_CMAKE_DIR})

# cpack -G DEB: rbsim_<version>_<arch>.deb, Depends from dpkg-shlibdeps.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME rbsim)
set(CPACK_PACKAGE_VENDOR "rbsim developers")
set(CPACK_PACKAGE_CONTACT "rbsim developers <rbsim@invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION
    "FOSSSim-style XML scenes run exactly, streamed live over DDS with ROS 2 conventions, recorded and
 replayed as MCAP in the rosbag2 layout, and checked against golden logs. Includes the rbsim
 command, its static libraries, headers and CMake package (find_package(rbsim)).")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Programs rbsim runs (movies, plots) and a font for frames; the -dev packages a CMake user of the
# static libraries links against.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "ffmpeg, gnuplot-nox, fonts-dejavu-core")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "cmake, pkg-config, libeigen3-dev, libtinyxml2-dev, libzstd-dev, liblz4-dev, libdeflate-dev, libssl-dev, libgtest-dev")
include(CPack)
