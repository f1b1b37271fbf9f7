# Install and export rules: find_package(tetseg) gives tetseg::format and tetseg::runtime.
include(CMakePackageConfigHelpers)
set(TETSEG_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/tetseg)

install(TARGETS tetseg_format tetseg_runtime EXPORT tetsegTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/formats/include/ ${PROJECT_SOURCE_DIR}/runtime/include/
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT tetsegTargets NAMESPACE tetseg:: DESTINATION ${TETSEG_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tetsegConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/tetsegConfig.cmake
                              INSTALL_DESTINATION ${TETSEG_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tetsegConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/tetsegConfig.cmake ${PROJECT_BINARY_DIR}/tetsegConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/TetsegAsset.cmake
        DESTINATION ${TETSEG_CMAKE_DIR})
# What users run in a pipeline (tools/); the benchmark drivers of bench/ are not installed.
foreach(tool tetseg tetseg-dump tetseg-render tetseg-frames tetseg-run)
  if(TARGET ${tool})
    install(TARGETS ${tool} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()
