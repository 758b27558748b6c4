# skinlab_embed_files(TARGET NAMESPACE ns BASE dir FILES f1 f2 ...)
# Generates a source file holding the bytes of each file and a lookup function
#   std::optional<std::string_view> ns::embeddedFile(std::string_view relativePath)
#   std::vector<std::string_view> ns::embeddedFileNames()
# and adds it to TARGET. Files are regenerated when they change.
function(skinlab_embed_files target)
  cmake_parse_arguments(ARG "" "NAMESPACE;BASE;NAME" "FILES" ${ARGN})
  if(NOT ARG_NAME)
    set(ARG_NAME ${target}_embedded)
  endif()
  set(out ${CMAKE_CURRENT_BINARY_DIR}/${ARG_NAME}.cpp)
  set(abs_files "")
  foreach(f IN LISTS ARG_FILES)
    list(APPEND abs_files ${ARG_BASE}/${f})
  endforeach()
  string(REPLACE ";" "|" files_arg "${ARG_FILES}")
  add_custom_command(
    OUTPUT ${out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${out} -DBASE=${ARG_BASE} -DNAMESPACE=${ARG_NAMESPACE}
            "-DFILES=${files_arg}" -P ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    DEPENDS ${abs_files} ${PROJECT_SOURCE_DIR}/cmake/embed_files.cmake
    COMMENT "Embedding ${ARG_NAME} (${ARG_NAMESPACE})"
    VERBATIM)
  target_sources(${target} PRIVATE ${out})
endfunction()
