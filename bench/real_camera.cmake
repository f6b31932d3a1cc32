# real_camera_evidence: the evidence tables of the real-camera chain (every correction left out in
# turn), the long part of what tests/e2e/real_camera_test.cc once ran; it prints them and fails
# when a correction does not matter. The chain and the tools' runner come from tests/e2e.
if(TARGET lumislab_e2e_test_util)
  find_package(GTest REQUIRED)
  add_executable(real_camera_evidence ${CMAKE_CURRENT_LIST_DIR}/real_camera_evidence.cc)
  target_include_directories(real_camera_evidence PRIVATE ${PROJECT_SOURCE_DIR}/tests/e2e)
  target_link_libraries(real_camera_evidence PRIVATE lumislab_e2e_test_util GTest::gtest_main)
  lumislab_warnings(real_camera_evidence)
  add_dependencies(real_camera_evidence lumislab-acquire lumislab-calibrate lumislab-reconstruct)
endif()
