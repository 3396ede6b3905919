# The installed CMake package: `find_package(gauss6 0.2 CONFIG REQUIRED)` then
# `target_link_libraries(app gauss6::core)`. Each library is a component with its own
# export set (gauss6-<component>-targets.cmake); gauss6Config.cmake finds the
# dependencies a component needs before loading its targets. The version is the
# top-level project()'s, the only place it is written.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(GAUSS6_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/gauss6)
# Installs TARGET as gauss6::COMPONENT, with the headers under the optional HEADERS_DIR
# (a folder holding gauss6/, installed whole so that new headers need no list; the
# caller's GAUSS6_PRIVATE_HEADERS, names of headers private to the library, stay out). Include
# folders of the source tree are kept for the build only; installed users get include/.
function(gauss6_export component target)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  if(dirs)
    set(wrapped)
    foreach(d IN LISTS dirs)
      if(d MATCHES "^\\$<")
        list(APPEND wrapped "${d}")
      else()
        list(APPEND wrapped "$<BUILD_INTERFACE:${d}>")
      endif()
    endforeach()
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${wrapped}")
  endif()
  target_include_directories(${target} INTERFACE $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${component})
  install(TARGETS ${target} EXPORT gauss6-${component}-targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT devel
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT devel)
  set(excluded)
  foreach(name IN LISTS GAUSS6_PRIVATE_HEADERS)
    list(APPEND excluded PATTERN ${name} EXCLUDE)
  endforeach()
  foreach(headers_dir IN LISTS ARGN)
    install(DIRECTORY ${headers_dir}/gauss6 DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT devel
      FILES_MATCHING PATTERN "*.h" ${excluded})
  endforeach()
  install(EXPORT gauss6-${component}-targets NAMESPACE gauss6::
    DESTINATION ${GAUSS6_INSTALL_CMAKEDIR} COMPONENT devel)
endfunction()

# The config and version files; called once every component is declared.
function(gauss6_install_package)
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/gauss6Config.cmake.in
    ${PROJECT_BINARY_DIR}/gauss6Config.cmake INSTALL_DESTINATION ${GAUSS6_INSTALL_CMAKEDIR})
  # 0.x: minor versions are not compatible with each other (SameMinorVersion).
  write_basic_package_version_file(${PROJECT_BINARY_DIR}/gauss6ConfigVersion.cmake
    VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/gauss6Config.cmake ${PROJECT_BINARY_DIR}/gauss6ConfigVersion.cmake
    DESTINATION ${GAUSS6_INSTALL_CMAKEDIR} COMPONENT devel)
endfunction()
