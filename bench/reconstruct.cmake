# reconstruct_bench: per-position decode time vs full reconstruction time (DESIGN §8).
add_executable(reconstruct_bench ${CMAKE_CURRENT_LIST_DIR}/reconstruct_bench.cc
               ${PROJECT_SOURCE_DIR}/tests/reconstruct/synthetic_dataset.cc)
target_include_directories(reconstruct_bench PRIVATE ${PROJECT_SOURCE_DIR}/tests/reconstruct)
target_link_libraries(reconstruct_bench PRIVATE lumislab_reconstruct)
lumislab_warnings(reconstruct_bench)
