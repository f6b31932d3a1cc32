# The merged light field of a luminaire folder (lib/lightfield/merged_far_field.h): time and peak
# memory against the number of orientations (GL-free).
if(TARGET lumislab_lightfield AND TARGET lumislab_synthetic)
  add_executable(merge_bench ${CMAKE_CURRENT_LIST_DIR}/merge_bench.cc)
  target_link_libraries(merge_bench PRIVATE lumislab_lightfield lumislab_synthetic)
  lumislab_warnings(merge_bench)
endif()
