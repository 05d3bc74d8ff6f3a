// libslamdunk_dense_pcl.so: the cloud files and the voxel filter through PCL, a plug-in the
// dense module loads the first time it needs them (PclCloudPlugin.cpp). The only translation
// unit that includes PCL.

#include "PclCloudFunctions.h"

#include <slamdunk/core/AtomicOutput.h>

#include <pcl/common/common.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <climits>
#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace slamdunk {

namespace {

using PclCloud = pcl::PointCloud<pcl::PointXYZRGB>;

PclCloud::Ptr toPcl(const DenseCloud& cloud) {
  auto out = std::make_shared<PclCloud>();
  out->reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    pcl::PointXYZRGB p;
    p.x = cloud.points[i].x();
    p.y = cloud.points[i].y();
    p.z = cloud.points[i].z();
    p.r = cloud.colours[i][0];
    p.g = cloud.colours[i][1];
    p.b = cloud.colours[i][2];
    out->push_back(p);
  }
  out->is_dense = true;  // every point is finite
  return out;
}

void appendFromPcl(const PclCloud& in, DenseCloud& out) {
  out.reserve(out.size() + in.size());
  for (const auto& p : in) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    out.add({p.x, p.y, p.z}, {p.r, p.g, p.b});
  }
}

// VoxelGrid numbers voxels with 32-bit ints and silently returns its input when the box has
// more than INT_MAX voxels (large maps at 1 cm). Voxels are aligned on multiples of the leaf
// size, so cutting the cloud at such a multiple and filtering each half gives the same result.
void voxelFilterInto(const PclCloud::Ptr& in, float leaf, DenseCloud& out) {
  if (in->empty()) return;
  Eigen::Vector4f lo, hi;
  pcl::getMinMax3D(*in, lo, hi);
  const Eigen::Array3d cells =
      ((hi - lo).head<3>().cast<double>().array() / leaf).floor() + 2.0;  // margin for rounding
  if (cells.prod() < double(INT_MAX) / 2) {
    pcl::VoxelGrid<pcl::PointXYZRGB> grid;
    grid.setInputCloud(in);
    grid.setLeafSize(leaf, leaf, leaf);
    PclCloud filtered;
    grid.filter(filtered);
    appendFromPcl(filtered, out);
    return;
  }
  int axis = 0;
  cells.maxCoeff(&axis);
  const float cut = std::floor((lo[axis] + hi[axis]) / 2 / leaf) * leaf;
  auto a = std::make_shared<PclCloud>(), b = std::make_shared<PclCloud>();
  for (const auto& p : *in) (p.getVector3fMap()[axis] < cut ? a : b)->push_back(p);
  if (a->empty() || b->empty()) throw std::runtime_error("voxel filter: cannot split the cloud");
  voxelFilterInto(a, leaf, out);
  voxelFilterInto(b, leaf, out);
}

bool hasExtension(const std::string& path, const std::string& ext) {
  std::string e = fs::path(path).extension().string();
  for (auto& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e == ext;
}

DenseCloud pclVoxelFilter(const DenseCloud& cloud, double voxelSize) {
  if (!(voxelSize > 0)) throw std::invalid_argument("voxel filter: voxel size must be > 0");
  DenseCloud out;
  voxelFilterInto(toPcl(cloud), float(voxelSize), out);
  return out;
}

void pclWritePly(const DenseCloud& cloud, const std::string& path, bool ascii) {
  if (cloud.empty()) throw std::runtime_error("cannot write '" + path + "': the cloud is empty");
  AtomicOutput out(path);
  pcl::PLYWriter writer;
  if (writer.write(out.tempPath(), *toPcl(cloud), !ascii, /*use_camera=*/false) != 0)
    throw std::runtime_error("cannot write PLY file '" + path + "'");
  // PCL's PLY writer does not report a failed write (a full disk leaves a short file that it
  // calls a success): read the file back, with PCL, before it may replace the user's.
  PclCloud back;
  if (pcl::io::loadPLYFile(out.tempPath(), back) < 0 || back.size() != cloud.size())
    throw std::runtime_error("cannot write PLY file '" + path + "': it was not written completely");
  out.commit();
}

void pclWritePcd(const DenseCloud& cloud, const std::string& path, bool ascii) {
  if (cloud.empty()) throw std::runtime_error("cannot write '" + path + "': the cloud is empty");
  AtomicOutput out(path);
  pcl::PCDWriter writer;
  const auto pcl = toPcl(cloud);
  int rc = -1;
  try {
    rc = ascii ? writer.writeASCII(out.tempPath(), *pcl) : writer.writeBinary(out.tempPath(), *pcl);
  } catch (const std::exception& e) {  // PCL throws when it cannot reserve the file's space
    throw std::runtime_error("cannot write PCD file '" + path + "': " + e.what());
  }
  if (rc != 0) throw std::runtime_error("cannot write PCD file '" + path + "'");
  out.commit();
}

DenseCloud pclReadPointCloud(const std::string& path) {
  if (!fs::is_regular_file(path)) throw std::runtime_error("point cloud '" + path + "' not found");
  PclCloud pcl;
  int rc = -1;
  if (hasExtension(path, ".ply"))
    rc = pcl::io::loadPLYFile(path, pcl);
  else if (hasExtension(path, ".pcd"))
    rc = pcl::io::loadPCDFile(path, pcl);
  else
    throw std::runtime_error("point cloud '" + path + "': expected a .ply or .pcd file");
  if (rc < 0) throw std::runtime_error("cannot read point cloud '" + path + "' (corrupt file?)");
  DenseCloud out;
  appendFromPcl(pcl, out);
  return out;
}

}  // namespace
}  // namespace slamdunk

extern "C" const slamdunk::PclCloudFunctions* slamdunkPclCloudFunctions() {
  static const slamdunk::PclCloudFunctions functions{&slamdunk::pclVoxelFilter,
                                                     &slamdunk::pclWritePly, &slamdunk::pclWritePcd,
                                                     &slamdunk::pclReadPointCloud};
  return &functions;
}
