# Installing vkrt as a system driver, and the Debian package (tools/package.sh: Release, CPack's DEB generator).
#
#   <prefix>/<libdir>/libvkrt.so                           the driver (Debian, prefix /usr: /usr/lib/x86_64-linux-gnu)
#   <prefix>/share/vulkan/icd.d/vkrt_icd.<arch>.json       the loader's manifest; library_path is the library's
#                                                          absolute installed path
#
# The library keeps its plain module name (SONAME libvkrt.so, no version suffix): nothing links against it; the
# loader dlopens the exact path its manifest names, so a versioned SONAME and a libvkrt.so.0 -> link pair would add
# files and no meaning (Debian's Mesa drivers, e.g. libvulkan_lvp.so, are installed the same way).
# Everything here is the `driver` component; the package holds that component only (never tests or examples).
install(TARGETS vkrt LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT driver)

# The manifest is written at install time, from the prefix the install runs with (`cmake --install --prefix`,
# CPack's packaging prefix), so that its path is where the library lands (cmake/VkrtInstallManifest.cmake).
install(CODE "
  set(VKRT_MANIFEST_LIBDIR \"${CMAKE_INSTALL_LIBDIR}\")
  set(VKRT_MANIFEST_DATADIR \"${CMAKE_INSTALL_DATADIR}\")
  set(VKRT_MANIFEST_LIBRARY \"$<TARGET_FILE_NAME:vkrt>\")
  set(VKRT_MANIFEST_NAME \"vkrt_icd.${CMAKE_SYSTEM_PROCESSOR}.json\")
  set(VKRT_MANIFEST_API_VERSION \"${VKRT_ICD_API_VERSION}\")
  set(VKRT_MANIFEST_STAGING \"${CMAKE_BINARY_DIR}/install-manifest\")
  include(\"${CMAKE_SOURCE_DIR}/cmake/VkrtInstallManifest.cmake\")
" COMPONENT driver)

# The Debian package: vkrt_<version>_<arch>.deb. dpkg-shlibdeps (dpkg-dev; CPack also needs `file`) computes the
# library dependencies (Embree, TBB, LLVM, libstdc++, ...); the loader is declared by hand, as Mesa's Vulkan
# drivers do: nothing links it, but no application reaches a driver without it.
set(VKRT_PACKAGE_MAINTAINER "vkrt maintainers <maintainers@users.noreply.h-seed-93c50a0f.example>" CACHE STRING
    "The Debian package's Maintainer field")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME vkrt)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
# (The long description: Debian wants lines under 80 characters; CPack keeps these as they are.)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "vkrt is a software Vulkan driver (an ICD: the standard Vulkan loader finds
it through its manifest in /usr/share/vulkan/icd.d) that runs ray tracing
pipelines, acceleration structures, ray queries and compute shaders on the
CPU (VK_KHR_ray_tracing_pipeline, VK_KHR_acceleration_structure,
VK_KHR_ray_query): acceleration structures on Embree, shaders compiled to
native code with LLVM. Applications see one physical device named vkrt
(device type CPU).")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION libs)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${VKRT_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS libvulkan1)
set(CPACK_STRIP_FILES ON)
# The files go where the build was configured to install them (tools/package.sh: /usr). CPack installs into its
# staging folder through DESTDIR, with CMAKE_INSTALL_PREFIX this prefix: the manifest names the real path.
set(CPACK_PACKAGING_INSTALL_PREFIX "${CMAKE_INSTALL_PREFIX}")
# CPack adds a postinst and a postrm that run ldconfig (it does so for any library in /usr/lib and its
# subfolders); harmless, and not needed: the loader opens the library by its absolute path. (Having a postrm,
# the package stays in dpkg's list as "rc" after `apt-get remove` until `apt-get purge`, as any such package.)
# Only the driver component (build dir; project; component; subdirectory).
set(CPACK_INSTALL_CMAKE_PROJECTS "${CMAKE_BINARY_DIR};vkrt;driver;/")
include(CPack)
