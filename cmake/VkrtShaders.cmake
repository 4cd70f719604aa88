# vkrt_embed_shaders(TARGET out_dir shader...): compiles each GLSL shader with glslc (Vulkan 1.3) and embeds
# the SPIR-V as `kSpv_<file name as an identifier>` in <out_dir>/<file>.spv.h; TARGET builds them all.
find_program(GLSLC glslc REQUIRED)

function(vkrt_embed_shaders target out_dir)
  file(MAKE_DIRECTORY ${out_dir})
  set(headers)
  foreach(shader ${ARGN})
    get_filename_component(fname ${shader} NAME)
    set(spv ${out_dir}/${fname}.spv)
    set(hdr ${out_dir}/${fname}.spv.h)
    string(MAKE_C_IDENTIFIER ${fname} ident)
    add_custom_command(
      OUTPUT ${hdr}
      COMMAND ${GLSLC} --target-env=vulkan1.3 -O -o ${spv} ${shader}
      COMMAND Python3::Interpreter ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py ${spv} ${hdr} kSpv_${ident}
      DEPENDS ${shader} ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py
      COMMENT "glslc ${fname}")
    list(APPEND headers ${hdr})
  endforeach()
  add_custom_target(${target} DEPENDS ${headers})
endfunction()
