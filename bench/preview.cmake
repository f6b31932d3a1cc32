# Preview benchmark: the paper's Table 1 redone through OSMesa (prints a table, writes CSV).
if(TARGET lumislab_preview)
  add_executable(preview_table1 ${CMAKE_CURRENT_LIST_DIR}/preview_table1.cc)
  target_link_libraries(preview_table1 PRIVATE lumislab_preview)
  lumislab_warnings(preview_table1)
endif()

if(TARGET lumislab_preview_renderer)
  # The renderer on a real GPU through EGL vs OSMesa; links neither (both are dlopen()ed), so the
  # binary and a few libraries can be carried to a GPU node.
  add_executable(preview_gpu_check ${CMAKE_CURRENT_LIST_DIR}/preview_gpu_check.cc)
  target_link_libraries(preview_gpu_check PRIVATE lumislab_preview_renderer lumislab_preview_egl
                        lumislab_lightfield
                        lumislab_synthetic ${CMAKE_DL_LIBS})
  lumislab_warnings(preview_gpu_check)
endif()

if(TARGET lumislab_preview)
  # A luminaire folder's preview against its number of orientations (docs/results.md §13).
  add_executable(preview_orientations ${CMAKE_CURRENT_LIST_DIR}/preview_orientations.cc)
  target_link_libraries(preview_orientations PRIVATE lumislab_preview)
  lumislab_warnings(preview_orientations)
endif()
