# vkrt_embed_shaders(TARGET out_dir shader... [SPV14 shader...]): compiles each GLSL shader with glslc (Vulkan 1.3),
# or assembles each SPIR-V assembly file with spirv-as (*.spvasm: SPIR-V 1.0, validated for Vulkan 1.0 with the
# block layouts VK_KHR_relaxed_block_layout allows; *.spv14.spvasm: SPIR-V 1.4, validated for Vulkan 1.1 with
# SPIR-V 1.4; *.newer.spvasm: SPIR-V 1.4 with tokens newer than SPIRV-Tools, left to the driver to validate; GLSL
# *.g.<stage>: compiled with -g, debug information and no optimization; GLSL *.gv.<stage>: compiled by glslangValidator
# -gV, NonSemantic.Shader.DebugInfo.100 debug information and no optimization), and
# embeds the SPIR-V as `kSpv_<file name as an identifier>` in <out_dir>/<file>.spv.h; TARGET builds them all. The GLSL
# shaders after SPV14 are compiled a second time as SPIR-V 1.4 modules (glslc --target-env=vulkan1.1
# --target-spv=spv1.4, what an application written for Vulkan 1.1 with VK_KHR_spirv_1_4 ships; unoptimized), embedded
# as `kSpv14_<identifier>` in <out_dir>/<file>.spv14.spv.h.
find_program(GLSLC glslc REQUIRED)
find_program(SPIRV_AS spirv-as REQUIRED)
find_program(SPIRV_VAL spirv-val REQUIRED)
find_program(GLSLANG_VALIDATOR glslangValidator REQUIRED)

function(vkrt_embed_shaders target out_dir)
  cmake_parse_arguments(ARG "" "" "SPV14" ${ARGN})
  file(MAKE_DIRECTORY ${out_dir})
  set(headers)
  foreach(variant default spv14)
    if(variant STREQUAL "default")
      set(shaders ${ARG_UNPARSED_ARGUMENTS})
    else()
      set(shaders ${ARG_SPV14})
    endif()
    foreach(shader ${shaders})
      get_filename_component(fname ${shader} NAME)
      # Headers a GLSL shader may #include (GL_GOOGLE_include_directive) from its own folder.
      get_filename_component(folder ${shader} DIRECTORY)
      file(GLOB includes CONFIGURE_DEPENDS ${folder}/*.glsl)
      string(MAKE_C_IDENTIFIER ${fname} ident)
      if(variant STREQUAL "spv14")
        set(spv ${out_dir}/${fname}.spv14.spv)
        set(hdr ${out_dir}/${fname}.spv14.spv.h)
        set(symbol kSpv14_${ident})
        set(comment "${fname} (SPIR-V 1.4)")
        # Not optimized: glslc's optimizer refuses SPIR-V 1.4 under Vulkan 1.1 ("Invalid SPIR-V binary version").
        set(build COMMAND ${GLSLC} --target-env=vulkan1.1 --target-spv=spv1.4 -o ${spv} ${shader})
      else()
        set(spv ${out_dir}/${fname}.spv)
        set(hdr ${out_dir}/${fname}.spv.h)
        set(symbol kSpv_${ident})
        set(comment "${fname}")
        if(fname MATCHES "\\.newer\\.spvasm$")
          # SPIR-V newer than the installed SPIRV-Tools (raw !words for its tokens, numeric ids that they name):
          # assembled as SPIR-V 1.4, validated by the driver when the test creates the module.
          set(build COMMAND ${SPIRV_AS} --target-env spv1.4 --preserve-numeric-ids -o ${spv} ${shader})
        elseif(fname MATCHES "\\.spv14\\.spvasm$")
          set(build COMMAND ${SPIRV_AS} --target-env spv1.4 -o ${spv} ${shader}
                    COMMAND ${SPIRV_VAL} --target-env vulkan1.1spv1.4 ${spv})
        elseif(fname MATCHES "\\.spvasm$")
          set(build COMMAND ${SPIRV_AS} --target-env spv1.0 -o ${spv} ${shader}
                    COMMAND ${SPIRV_VAL} --target-env vulkan1.0 --relax-block-layout ${spv})
        elseif(fname MATCHES "\\.gv\\.[a-z]+$")
          # *.gv.<stage>: with NonSemantic.Shader.DebugInfo.100 debug information (glslangValidator -gV: DebugSource,
          # DebugLine; the newer form of `-g`), not optimized.
          set(build COMMAND ${GLSLANG_VALIDATOR} -V --target-env vulkan1.3 -gV --quiet -o ${spv} ${shader})
        elseif(fname MATCHES "\\.g\\.[a-z]+$")
          # *.g.<stage>: with debug information (glslc -g: OpSource with the text, OpString file names, OpLine),
          # not optimized, as an application builds shaders to debug them.
          set(build COMMAND ${GLSLC} --target-env=vulkan1.3 -g -o ${spv} ${shader})
        else()
          set(build COMMAND ${GLSLC} --target-env=vulkan1.3 -O -o ${spv} ${shader})
        endif()
      endif()
      add_custom_command(
        OUTPUT ${hdr}
        ${build}
        COMMAND Python3::Interpreter ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py ${spv} ${hdr} ${symbol}
        DEPENDS ${shader} ${includes} ${CMAKE_SOURCE_DIR}/tools/embed_spirv.py
        COMMENT "${comment}")
      list(APPEND headers ${hdr})
    endforeach()
  endforeach()
  add_custom_target(${target} DEPENDS ${headers})
endfunction()
