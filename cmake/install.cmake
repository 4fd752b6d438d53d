# The installed CMake package: `cmake --install build --prefix P` puts the engine, systems and
# API static libraries in P/lib, their headers in P/include/ballpit/{engine,systems,api} (they
# include each other as "engine/x.h", so P/include/ballpit is the include directory the targets
# carry), the model probe in P/libexec/ballpit, and the package files in P/lib/cmake/ballpit.
# Another project then writes find_package(ballpit 1.0 REQUIRED) and links ballpit::ballpit
# (examples/hello_pit). Targets: ballpit::engine, ballpit::systems, ballpit::api, ballpit::ballpit
# (all of them), ballpit::model-probe. The package is relocatable: every path in it is relative
# to where its files lie. The Python module installs from python/CMakeLists.txt, to
# P/lib/python3/dist-packages.
include(CMakePackageConfigHelpers)

set(BALLPIT_PACKAGE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/ballpit)
set(BALLPIT_PROBE_DIR ${CMAKE_INSTALL_LIBEXECDIR}/ballpit)

set_target_properties(ballpit_engine PROPERTIES EXPORT_NAME engine)
set_target_properties(ballpit_systems PROPERTIES EXPORT_NAME systems)
set_target_properties(ballpit_api PROPERTIES EXPORT_NAME api)
set_target_properties(ballpit-model-probe PROPERTIES EXPORT_NAME model-probe)
# A program that includes engine headers compiles their inline arithmetic itself: it must round
# as the libraries do (CMakeLists.txt: no fused multiply-adds), or states would depend on it.
target_compile_options(ballpit_engine INTERFACE $<INSTALL_INTERFACE:-ffp-contract=off>)

install(TARGETS ballpit_engine ballpit_systems ballpit_api ballpit_package EXPORT ballpitTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(TARGETS ballpit-model-probe EXPORT ballpitTargets RUNTIME DESTINATION ${BALLPIT_PROBE_DIR})
foreach(folder engine systems api)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/ballpit/${folder}
          FILES_MATCHING PATTERN "*.h")
endforeach()
install(EXPORT ballpitTargets NAMESPACE ballpit:: DESTINATION ${BALLPIT_PACKAGE_DIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ballpitConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/ballpitConfig.cmake
                              INSTALL_DESTINATION ${BALLPIT_PACKAGE_DIR} PATH_VARS BALLPIT_PROBE_DIR)
# 1.x serves any request for 1.y with y <= x; 2.0 would be a new API.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ballpitConfigVersion.cmake COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/ballpitConfig.cmake ${PROJECT_BINARY_DIR}/ballpitConfigVersion.cmake
        DESTINATION ${BALLPIT_PACKAGE_DIR})
