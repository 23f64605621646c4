# `cmake --install`: the stage libraries, their headers and a CMake package, so that another
# project can `find_package(relight)` and link relight::core, relight::render, ... (exported
# names below; tests/install/ builds a consumer against an installed tree). The CLI, the test-only
# truth/ and synth/ libraries, and the OpenNI2 plugin are not part of the package.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(relight_exported core:relight_core vk:relight_vk capture:relight_capture reconstruct:relight_reconstruct
    lights:relight_lights colormap:relight_colormap brdf:relight_brdf models:relight_models render:relight_render)
set(relight_installed_targets)
foreach(entry IN LISTS relight_exported)
  string(REPLACE ":" ";" pair ${entry})
  list(GET pair 0 export_name)
  list(GET pair 1 target)
  if(TARGET ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
    list(APPEND relight_installed_targets ${target})
  endif()
endforeach()

install(TARGETS ${relight_installed_targets} EXPORT relightTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
foreach(folder core core/vk capture reconstruct lights colormap brdf render)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder}/include/relight DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

set(package_dir ${CMAKE_INSTALL_LIBDIR}/cmake/relight)
install(EXPORT relightTargets NAMESPACE relight:: DESTINATION ${package_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/relightConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/relightConfig.cmake INSTALL_DESTINATION ${package_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/relightConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/relightConfig.cmake ${PROJECT_BINARY_DIR}/relightConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindOpenCVModules.cmake
        DESTINATION ${package_dir})
