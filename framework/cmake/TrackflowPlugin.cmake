# trackflow_add_plugin(<name> SOURCES <files...> [LIBRARIES <targets...>])
# Builds tfplugin_<name>.so against trackflow::sdk with hidden visibility, the way the host
# expects to find it. In the trackflow tree it lands in the build's plugin folder; elsewhere in
# the caller's binary dir (point --plugin-path or TRACKFLOW_PLUGIN_PATH there).
function(trackflow_add_plugin name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBRARIES" ${ARGN})
  if(NOT ARG_SOURCES)
    message(FATAL_ERROR "trackflow_add_plugin(${name}): SOURCES is required")
  endif()
  set(target tfplugin_${name})
  add_library(${target} MODULE ${ARG_SOURCES})
  target_link_libraries(${target} PRIVATE trackflow::sdk ${ARG_LIBRARIES})
  set_target_properties(${target} PROPERTIES
    PREFIX ""
    OUTPUT_NAME ${target}
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    CXX_STANDARD 20
    CXX_STANDARD_REQUIRED ON)
  # In the trackflow tree a plugin must link against the SDK alone: an unresolved symbol (one the
  # host library defines, say) is a link error here rather than a load error in someone's run.
  # Not under the sanitizers, whose runtime symbols a module leaves to the executable.
  if(DEFINED TRACKFLOW_PLUGIN_BUILD_DIR AND NOT CMAKE_CXX_FLAGS MATCHES "sanitize")
    target_link_options(${target} PRIVATE -Wl,--no-undefined)
  endif()
  if(DEFINED TRACKFLOW_PLUGIN_BUILD_DIR)
    set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${TRACKFLOW_PLUGIN_BUILD_DIR})
  endif()
  if(DEFINED TRACKFLOW_PLUGIN_INSTALL_DIR)
    install(TARGETS ${target} LIBRARY DESTINATION ${TRACKFLOW_PLUGIN_INSTALL_DIR})
  endif()
endfunction()

