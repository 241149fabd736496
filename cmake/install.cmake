# `cmake --install`: the layer libraries (static) with their headers under include/orthoface/,
# the CMake package (lib/cmake/orthoface, targets orthoface::<layer>), orthoface.pc, the
# command-line binaries and the trained weights vision reads at run time.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ORTHOFACE_LAYERS io capture vision mesh model analysis render reconstruct sim)  # lowest first
set(ORTHOFACE_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/orthoface)
set(ORTHOFACE_INSTALL_MODELDIR ${CMAKE_INSTALL_DATADIR}/orthoface/models)

set(layer_targets "")
set(pc_libs "")
foreach(layer IN LISTS ORTHOFACE_LAYERS)
  set_target_properties(orthoface_${layer} PROPERTIES EXPORT_NAME ${layer})
  # The headers use C++20 (designated initialisers, std::span): consumers compile them so too.
  target_compile_features(orthoface_${layer} PUBLIC cxx_std_20)
  file(GLOB headers CONFIGURE_DEPENDS ${ORTHOFACE_ROOT}/${layer}/*.h)
  install(FILES ${headers} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/orthoface/${layer})
  list(APPEND layer_targets orthoface_${layer})
  set(pc_libs "-lorthoface_${layer} ${pc_libs}")  # a static library before the ones it uses
endforeach()

# Headers include each other as "mesh/tri_mesh.h"; consumers may write either that or
# <orthoface/mesh/tri_mesh.h>.
install(TARGETS ${layer_targets} EXPORT orthofaceTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} ${CMAKE_INSTALL_INCLUDEDIR}/orthoface)
install(EXPORT orthofaceTargets NAMESPACE orthoface:: DESTINATION ${ORTHOFACE_INSTALL_CMAKEDIR})

install(TARGETS orthoface RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
if(TARGET orthoface-batch)
  install(TARGETS orthoface-batch RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()
install(DIRECTORY ${ORTHOFACE_ROOT}/vision/models/ DESTINATION ${ORTHOFACE_INSTALL_MODELDIR})

if(TARGET PkgConfig::LIBCAMERA)
  set(ORTHOFACE_HAVE_LIBCAMERA TRUE)
  set(ORTHOFACE_LIBCAMERA_NOTE " and libcamera (libcamera-dev)")
else()
  set(ORTHOFACE_HAVE_LIBCAMERA FALSE)
  set(ORTHOFACE_LIBCAMERA_NOTE "")
endif()
configure_package_config_file(
  ${ORTHOFACE_ROOT}/cmake/orthofaceConfig.cmake.in ${CMAKE_BINARY_DIR}/orthofaceConfig.cmake
  INSTALL_DESTINATION ${ORTHOFACE_INSTALL_CMAKEDIR} PATH_VARS ORTHOFACE_INSTALL_MODELDIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/orthofaceConfigVersion.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${CMAKE_BINARY_DIR}/orthofaceConfig.cmake
              ${CMAKE_BINARY_DIR}/orthofaceConfigVersion.cmake
        DESTINATION ${ORTHOFACE_INSTALL_CMAKEDIR})

# pkg-config: paths relative to the .pc file, so the prefix given to `cmake --install` holds.
file(RELATIVE_PATH ORTHOFACE_PC_TO_PREFIX /prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig /prefix)
string(REGEX REPLACE "/$" "" ORTHOFACE_PC_TO_PREFIX "${ORTHOFACE_PC_TO_PREFIX}")
string(STRIP "${pc_libs}" ORTHOFACE_PC_LIBS)
set(ORTHOFACE_PC_REQUIRES "opencv4 eigen3 nlohmann_json tinygltf osmesa dlib-1")
set(ORTHOFACE_PC_DEFINES "")
if(ORTHOFACE_HAVE_LIBCAMERA)
  string(APPEND ORTHOFACE_PC_REQUIRES " libcamera")
  set(ORTHOFACE_PC_DEFINES " -DORTHOFACE_HAVE_LIBCAMERA")  # as orthoface::capture's users get
endif()
configure_file(${ORTHOFACE_ROOT}/cmake/orthoface.pc.in ${CMAKE_BINARY_DIR}/orthoface.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/orthoface.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
