# stepnc_embed(<out-var> <symbol> <input-file> [DEPENDS ...])
# Adds a build rule that turns <input-file> into a generated C++ source defining
# stepnc::embedded::<symbol> and <symbol>_size, and appends that source to <out-var>.
function(stepnc_embed out_var symbol input)
  cmake_parse_arguments(ARG "" "" "DEPENDS" ${ARGN})
  set(output ${CMAKE_CURRENT_BINARY_DIR}/embedded/${symbol}.cpp)
  add_custom_command(
    OUTPUT ${output}
    COMMAND ${CMAKE_COMMAND} -DINPUT=${input} -DOUTPUT=${output} -DSYMBOL=${symbol}
            -P ${PROJECT_SOURCE_DIR}/cmake/EmbedFile.cmake
    DEPENDS ${input} ${PROJECT_SOURCE_DIR}/cmake/EmbedFile.cmake ${ARG_DEPENDS}
    COMMENT "Embedding ${symbol}"
    VERBATIM)
  set(${out_var} ${${out_var}} ${output} PARENT_SCOPE)
endfunction()
