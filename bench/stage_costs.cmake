# stage_costs: how each batch stage's CPU time and peak memory grow with positions, photo size,
# slab resolution and threads, and the fit that pipelines/stage_resources.py requests Slurm
# resources from (docs/results.md §14). `cmake --build build --target stage_costs` runs it,
# niced, into build/stage_costs/ (about 5 min wall, under 2 min of CPU on 2 cores).
find_package(Python3 COMPONENTS Interpreter)
if(Python3_FOUND AND TARGET lumislab-preview)
  add_custom_target(stage_costs
    COMMAND nice -n 19 ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/stage_costs.py
            --bin ${CMAKE_BINARY_DIR}/bin --out ${CMAKE_BINARY_DIR}/stage_costs
    DEPENDS lumislab-acquire lumislab-calibrate lumislab-reconstruct lumislab-export
            lumislab-preview
    USES_TERMINAL)
endif()
