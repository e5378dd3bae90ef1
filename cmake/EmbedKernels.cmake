# embed_kernels(OUT KERNEL_DIR dir RANDOM123_DIR dir)
# Writes OUT, a C++ file defining misalloc::embeddedSources(): the text of every
# kernels/*.cl and kernels/*.h, plus the Random123 headers the kernels include,
# keyed by their include path ("estimator.h", "Random123/philox.h").
function(embed_kernels OUT)
  cmake_parse_arguments(EK "" "KERNEL_DIR;RANDOM123_DIR" "" ${ARGN})
  file(GLOB kernel_files CONFIGURE_DEPENDS ${EK_KERNEL_DIR}/*.cl ${EK_KERNEL_DIR}/*.h)
  set(r123_names philox.h array.h features/compilerfeatures.h features/openclfeatures.h features/sse.h)
  set(entries "")
  set(deps "")
  foreach(f ${kernel_files})
    get_filename_component(name ${f} NAME)
    list(APPEND entries "${name}|${f}")
    list(APPEND deps ${f})
  endforeach()
  foreach(name ${r123_names})
    list(APPEND entries "Random123/${name}|${EK_RANDOM123_DIR}/${name}")
    list(APPEND deps ${EK_RANDOM123_DIR}/${name})
  endforeach()
  string(REPLACE ";" "\n" entries_text "${entries}")
  file(WRITE ${CMAKE_BINARY_DIR}/generated/embed_list.txt "${entries_text}\n")
  add_custom_command(OUTPUT ${OUT}
    COMMAND ${CMAKE_COMMAND} -DLIST=${CMAKE_BINARY_DIR}/generated/embed_list.txt -DOUT=${OUT}
            -P ${CMAKE_SOURCE_DIR}/cmake/WriteEmbedded.cmake
    DEPENDS ${deps} ${CMAKE_SOURCE_DIR}/cmake/WriteEmbedded.cmake ${CMAKE_BINARY_DIR}/generated/embed_list.txt
    COMMENT "Embedding kernel sources")
endfunction()
