# Installs what a plugin author needs for find_package(mneedle): the C ABI header and the
# mneedle::plugin_api interface target (see docs/plugins.md). The libraries stay internal.
include(CMakePackageConfigHelpers)

install(EXPORT mneedleTargets NAMESPACE mneedle:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/mneedleConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/mneedleConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle)
