# reconstruct_bench: per-position decode time vs full reconstruction time (docs/testing.md).
# Its datasets come from the reconstruct tests' analytic dataset library; the camera photos
# (JPEG, TIFF, DNG) are written with lib/photo's camera writers.
if(TARGET lumislab_reconstruct_testdata)
  add_executable(reconstruct_bench ${CMAKE_CURRENT_LIST_DIR}/reconstruct_bench.cc
                                   ${CMAKE_CURRENT_LIST_DIR}/camera_dataset.cc)
  target_link_libraries(reconstruct_bench PRIVATE lumislab_reconstruct_testdata lumislab_photo)
  lumislab_warnings(reconstruct_bench)
else()
  message(STATUS "reconstruct_bench needs LUMISLAB_BUILD_TESTS (its datasets come from there)")
endif()
