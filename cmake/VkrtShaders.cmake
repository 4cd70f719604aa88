# vkrt_embed_shaders(TARGET out_dir shader...): compiles each GLSL shader with glslc (Vulkan 1.3), or assembles
# each SPIR-V assembly file (*.spvasm, SPIR-V 1.0, validated for Vulkan 1.0) with spirv-as, and embeds the
# SPIR-V as `kSpv_<file name as an identifier>` in <out_dir>/<file>.spv.h; TARGET builds them all.
find_program(GLSLC glslc REQUIRED)
find_program(SPIRV_AS spirv-as REQUIRED)
find_program(SPIRV_VAL spirv-val REQUIRED)

function(vkrt_embed_shaders target out_dir)
  file(MAKE_DIRECTORY ${out_dir})
  set(headers)
  foreach(shader ${ARGN})
    get_filename_component(fname ${shader} NAME)
    # Headers a GLSL shader may #include (GL_GOOGLE_include_directive) from its own folder.
    get_filename_component(folder ${shader} DIRECTORY)
    file(GLOB includes CONFIGURE_DEPENDS ${folder}/*.glsl)
    set(spv ${out_dir}/${fname}.spv)
    set(hdr ${out_dir}/${fname}.spv.h)
    string(MAKE_C_IDENTIFIER ${fname} ident)
    if(fname MATCHES "\\.spvasm$")
      set(build COMMAND ${SPIRV_AS} --target-env spv1.0 -o ${spv} ${shader}
                COMMAND ${SPIRV_VAL} --target-env vulkan1.0 ${spv})
    else()
      set(build COMMAND ${GLSLC} --target-env=vulkan1.3 -O -o ${spv} ${shader})
    endif()
    add_custom_command(
      OUTPUT ${hdr}
      ${build}
      COMMAND Python3::Interpreter ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py ${spv} ${hdr} kSpv_${ident}
      DEPENDS ${shader} ${includes} ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py
      COMMENT "${fname}")
    list(APPEND headers ${hdr})
  endforeach()
  add_custom_target(${target} DEPENDS ${headers})
endfunction()
