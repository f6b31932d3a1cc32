# The exact CPU reference: time and error against the analytic truth per samples per basis
# support (GL-free: lib/lightfield and lib/synthetic only).
if(TARGET lumislab_lightfield AND TARGET lumislab_synthetic)
  add_executable(reference_table ${CMAKE_CURRENT_LIST_DIR}/reference_table.cc)
  target_link_libraries(reference_table PRIVATE lumislab_lightfield lumislab_synthetic)
  lumislab_warnings(reference_table)
endif()
