#pragma once
// What the PCL plug-in (PclCloudIo.cpp) gives the dense module (PclCloudPlugin.cpp).

#include <slamdunk/dense/DenseReconstruction.h>

#include <string>

namespace slamdunk {

struct PclCloudFunctions {
  DenseCloud (*voxelFilter)(const DenseCloud& cloud, double voxelSize);
  void (*writePly)(const DenseCloud& cloud, const std::string& path, bool ascii);
  void (*writePcd)(const DenseCloud& cloud, const std::string& path, bool ascii);
  DenseCloud (*readPointCloud)(const std::string& path);
};

/// The plug-in's entry point (C linkage, looked up by name).
constexpr const char* kPclCloudFunctionsSymbol = "slamdunkPclCloudFunctions";
constexpr const char* kPclCloudPlugin = "libslamdunk_dense_pcl.so";

}  // namespace slamdunk
