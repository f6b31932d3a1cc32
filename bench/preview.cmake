# Preview benchmark: the paper's Table 1 redone through OSMesa (prints a table, writes CSV).
if(TARGET lumislab_preview)
  add_executable(preview_table1 ${CMAKE_CURRENT_LIST_DIR}/preview_table1.cc)
  target_link_libraries(preview_table1 PRIVATE lumislab_preview)
  lumislab_warnings(preview_table1)
endif()
