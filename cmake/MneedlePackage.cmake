# Installs what a plugin author needs for find_package(mneedle): the C ABI header and the
# mneedle::plugin_api interface target (see docs/plugins.md), all in the install component
# `plugin_dev` (`cmake --install <build> --component plugin_dev --prefix <dir>`). The
# libraries stay internal.
include(CMakePackageConfigHelpers)

# The ABI major version, read from the header so that the two never disagree.
file(STRINGS ${PROJECT_SOURCE_DIR}/geometry_plugins/include/mneedle/plugin.h _mneedle_abi_line
     REGEX "^#define MNEEDLE_PLUGIN_ABI_MAJOR [0-9]+")
string(REGEX REPLACE ".* ([0-9]+)$" "\\1" MNEEDLE_PLUGIN_ABI_MAJOR "${_mneedle_abi_line}")

install(EXPORT mneedleTargets NAMESPACE mneedle:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle
        COMPONENT plugin_dev)
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/mneedleConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle)
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/mneedleConfigVersion.cmake
  COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/mneedleConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/mneedle COMPONENT plugin_dev)
