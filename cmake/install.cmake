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
# The bundled scenes: rbsim node's worlds folder by default (get_available_worlds, load_world's uri).
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim/scenes
        FILES_MATCHING PATTERN "*.xml")

# A package of a ROS 2 workspace (package.xml, colcon.pkg; colcon builds it as plain CMake, no ament):
# what ROS 2's tools look up through the ament index under an AMENT_PREFIX_PATH entry.
#  - `ros2 run rbsim rbsim` runs lib/rbsim/rbsim: a relative link to bin/rbsim, so the binary is
#    stored once and still finds share/rbsim beside its real path (/proc/self/exe).
#  - The index's markers: packages/<pkg> (empty) for rbsim and rbsim_msgs, and rosidl_interfaces/
#    rbsim_msgs listing its definitions one per line (msg/BodyStates.msg), as rosidl registers them.
#  - share/rbsim_msgs: the .msg and .srv files rbsim defines, byte for byte (`ros2 interface show`
#    reads them; no generated code), and a package.xml, as every indexed package has.
#  - share/rbsim/hook: the environment hook colcon.pkg names, putting the prefix on
#    AMENT_PREFIX_PATH when the workspace is sourced (colcon does that for ament packages only).
# Only rbsim_msgs is installed of tools/msgs/definitions: the other packages there (std_msgs,
# simulation_interfaces, ...) are copies of ROS 2's own, which a sourced ROS 2 already has; a
# second share/std_msgs would shadow or clash with the real one.
set(RBSIM_ROS_BUILD ${PROJECT_BINARY_DIR}/ros)
file(RELATIVE_PATH RBSIM_EXE_FROM_LIB /prefix/lib/rbsim /prefix/${CMAKE_INSTALL_BINDIR}/rbsim)
file(MAKE_DIRECTORY ${RBSIM_ROS_BUILD}/lib)
file(CREATE_LINK ${RBSIM_EXE_FROM_LIB} ${RBSIM_ROS_BUILD}/lib/rbsim SYMBOLIC)
install(FILES ${RBSIM_ROS_BUILD}/lib/rbsim DESTINATION lib/rbsim)
set(RBSIM_MSGS_DIR ${PROJECT_SOURCE_DIR}/tools/msgs/definitions/rbsim_msgs)
file(GLOB RBSIM_MSGS_FILES RELATIVE ${RBSIM_MSGS_DIR} CONFIGURE_DEPENDS ${RBSIM_MSGS_DIR}/msg/*.msg
     ${RBSIM_MSGS_DIR}/srv/*.srv ${RBSIM_MSGS_DIR}/action/*.action)
list(SORT RBSIM_MSGS_FILES)
list(JOIN RBSIM_MSGS_FILES "\n" RBSIM_MSGS_INDEX)
file(CONFIGURE OUTPUT ${RBSIM_ROS_BUILD}/rosidl_interfaces/rbsim_msgs CONTENT "${RBSIM_MSGS_INDEX}\n" @ONLY)
file(CONFIGURE OUTPUT ${RBSIM_ROS_BUILD}/packages/rbsim CONTENT "")
file(CONFIGURE OUTPUT ${RBSIM_ROS_BUILD}/packages/rbsim_msgs CONTENT "")
configure_file(${PROJECT_SOURCE_DIR}/cmake/ros/rbsim_msgs.package.xml.in ${RBSIM_ROS_BUILD}/rbsim_msgs/package.xml @ONLY)
set(RBSIM_AMENT_INDEX ${CMAKE_INSTALL_DATADIR}/ament_index/resource_index)
install(FILES ${RBSIM_ROS_BUILD}/packages/rbsim ${RBSIM_ROS_BUILD}/packages/rbsim_msgs
        DESTINATION ${RBSIM_AMENT_INDEX}/packages)
install(FILES ${RBSIM_ROS_BUILD}/rosidl_interfaces/rbsim_msgs DESTINATION ${RBSIM_AMENT_INDEX}/rosidl_interfaces)
install(DIRECTORY ${RBSIM_MSGS_DIR}/ DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim_msgs)
install(FILES ${RBSIM_ROS_BUILD}/rbsim_msgs/package.xml DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim_msgs)
install(FILES ${PROJECT_SOURCE_DIR}/package.xml DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim)
install(FILES ${PROJECT_SOURCE_DIR}/cmake/ros/ament_prefix_path.dsv ${PROJECT_SOURCE_DIR}/cmake/ros/ament_prefix_path.sh
        DESTINATION ${CMAKE_INSTALL_DATADIR}/rbsim/hook)

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
