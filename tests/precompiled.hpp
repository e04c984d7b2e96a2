// What most unit-test files parse first, precompiled once for simsoccer_unit_tests
// (tests/CMakeLists.txt): at -O0 (the sanitizer build) parsing is half a file's build time.
#pragma once
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>
