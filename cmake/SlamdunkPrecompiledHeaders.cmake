# Precompiled headers: the third-party and standard headers that nearly every translation unit
# includes. Parsing them took most of the build (a file that includes only
# slamdunk/slam/SlamSystem.h compiles in 7 s at -O3), so they are compiled once per kind of
# target and reused: libraries (-fPIC), programs (-fPIE) and test drivers (-fPIE, -O1, gtest).
# GCC uses a precompiled header only where these flags match, hence three. Only third-party
# headers: a source file sees nothing of this project it did not include itself.
option(SLAMDUNK_PRECOMPILED_HEADERS "Compile the common third-party headers once" ON)

set(SLAMDUNK_PCH_HEADERS
  <algorithm> <array> <atomic> <chrono> <cmath> <condition_variable> <cstdint> <cstdio>
  <cstdlib> <cstring> <deque> <filesystem> <fstream> <functional> <iostream> <map> <memory>
  <mutex> <optional> <random> <set> <sstream> <stdexcept> <string> <thread> <unordered_map>
  <utility> <vector>
  <Eigen/Core> <Eigen/Geometry>
  <opencv2/core.hpp> <opencv2/imgproc.hpp>
  <mrpt/config/CConfigFileBase.h> <mrpt/img/CImage.h> <mrpt/obs/CObservation3DRangeScan.h>
  <mrpt/poses/CPose3D.h> <mrpt/serialization/CArchive.h> <mrpt/system/datetime.h>)

# slamdunk_pch_base(NAME [PIE] [TEST]): an object library that only compiles the headers.
function(slamdunk_pch_base NAME)
  cmake_parse_arguments(ARG "PIE;TEST" "" "" ${ARGN})
  add_library(${NAME} OBJECT ${PROJECT_SOURCE_DIR}/cmake/pch/empty.cpp)
  target_link_libraries(${NAME} PRIVATE mrpt::obs mrpt::poses mrpt::img mrpt::config
    Eigen3::Eigen ${OpenCV_LIBS})
  target_include_directories(${NAME} SYSTEM PRIVATE ${OpenCV_INCLUDE_DIRS})
  set(headers ${SLAMDUNK_PCH_HEADERS})
  if(ARG_PIE)
    # As CMake compiles the programs' sources (CMAKE_POSITION_INDEPENDENT_CODE).
    set_target_properties(${NAME} PROPERTIES POSITION_INDEPENDENT_CODE OFF)
    target_compile_options(${NAME} PRIVATE -fPIE)
  endif()
  if(ARG_TEST)
    target_link_libraries(${NAME} PRIVATE GTest::gtest)
    target_compile_options(${NAME} PRIVATE -O1)  # as slamdunk_test_compile_options
    list(APPEND headers <gtest/gtest.h>)
  endif()
  target_precompile_headers(${NAME} PRIVATE ${headers})
endfunction()

# slamdunk_use_pch(TARGET KIND): KIND is lib, exe or test.
function(slamdunk_use_pch TARGET KIND)
  if(SLAMDUNK_PRECOMPILED_HEADERS)
    target_precompile_headers(${TARGET} REUSE_FROM slamdunk_pch_${KIND})
  endif()
endfunction()

if(SLAMDUNK_PRECOMPILED_HEADERS)
  slamdunk_pch_base(slamdunk_pch_lib)
  slamdunk_pch_base(slamdunk_pch_exe PIE)
endif()
