# reconstruct_bench: per-position decode time vs full reconstruction time (docs/design.md §8).
# Its datasets come from the reconstruct tests' analytic dataset library.
if(TARGET lumislab_reconstruct_testdata)
  add_executable(reconstruct_bench ${CMAKE_CURRENT_LIST_DIR}/reconstruct_bench.cc)
  target_link_libraries(reconstruct_bench PRIVATE lumislab_reconstruct_testdata)
  lumislab_warnings(reconstruct_bench)
else()
  message(STATUS "reconstruct_bench needs LUMISLAB_BUILD_TESTS (its datasets come from there)")
endif()
