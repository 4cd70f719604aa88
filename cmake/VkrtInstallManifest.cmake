# Runs at install time (cmake/VkrtInstall.cmake's install(CODE)): writes the loader's manifest for the installed
# library and installs it in <prefix>/<datadir>/vulkan/icd.d. library_path is absolute: the loader resolves a bare
# file name through the dynamic linker's search path and a relative path against the manifest's folder; the
# absolute path is the one that names this library and no other.
set(libdir "${VKRT_MANIFEST_LIBDIR}")
if(NOT IS_ABSOLUTE "${libdir}")
  set(libdir "${CMAKE_INSTALL_PREFIX}/${libdir}")
endif()
set(datadir "${VKRT_MANIFEST_DATADIR}")
if(NOT IS_ABSOLUTE "${datadir}")
  set(datadir "${CMAKE_INSTALL_PREFIX}/${datadir}")
endif()
cmake_path(SET library NORMALIZE "${libdir}/${VKRT_MANIFEST_LIBRARY}")
cmake_path(SET icddir NORMALIZE "${datadir}/vulkan/icd.d")
file(WRITE "${VKRT_MANIFEST_STAGING}/${VKRT_MANIFEST_NAME}" "{
    \"file_format_version\": \"1.0.0\",
    \"ICD\": {
        \"library_path\": \"${library}\",
        \"api_version\": \"${VKRT_MANIFEST_API_VERSION}\"
    }
}
")
file(INSTALL DESTINATION "${icddir}" TYPE FILE FILES "${VKRT_MANIFEST_STAGING}/${VKRT_MANIFEST_NAME}")
