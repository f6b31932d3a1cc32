// The headers nearly every test driver parses, precompiled once for all of them
// (tests/CMakeLists.txt, LUMISLAB_TEST_PCH). Third-party and standard headers only: a change to
// a lumislab header must not rebuild the precompiled header and with it every driver. Not
// OpenCV's imgcodecs: the drivers that use it include it, and link it (tests/CMakeLists.txt).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>
