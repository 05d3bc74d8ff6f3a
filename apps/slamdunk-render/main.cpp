// slamdunk-render: renders a saved SlamDunk map (CKeyframeGraphMap file), or a .ply/.pcd cloud,
// offscreen to a PNG: coloured cloud, keyframe frustums, graph edges, optional trajectory.

#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/TumTrajectory.h>
#include <slamdunk/dense/MapRenderer.h>
#include <slamdunk/mrpt_map/CKeyframeGraphMap.h>

#include <mrpt/opengl/COpenGLScene.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>

namespace fs = std::filesystem;
using namespace slamdunk;

namespace {

std::string lowerExtension(const std::string& path) {
  std::string e = fs::path(path).extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  const char* tool = "slamdunk-render";
  try {
    TCLAP::CmdLine cmd(
        "Renders a SlamDunk map offscreen (no display needed) to a PNG. MAP is a keyframe map "
        "saved by slamdunk-rawlog (CKeyframeGraphMap file): its keyframes that kept their images "
        "give a dense coloured cloud (voxel-filtered), otherwise their feature points are shown; "
        "keyframes are drawn as frustums, graph edges as green lines. MAP may also be a .ply or "
        ".pcd cloud. The view is z-up and, by default, frames the whole map.",
        ' ', "1.0");
    TCLAP::UnlabeledValueArg<std::string> argMap("MAP", "map file (or .ply/.pcd cloud)", true, "",
                                                 "MAP", cmd);
    TCLAP::UnlabeledValueArg<std::string> argOut("OUT", "output PNG", true, "", "OUT.png", cmd);
    TCLAP::ValueArg<int> argWidth("", "width", "image width in pixels (16..8192)", false, 1024, "W",
                                  cmd);
    TCLAP::ValueArg<int> argHeight("", "height", "image height in pixels (16..8192)", false, 768,
                                   "H", cmd);
    TCLAP::ValueArg<std::string> argScene(
        "", "scene", "also save the scene for SceneViewer3D (gz-compressed COpenGLScene)", false,
        "", "OUT.3Dscene", cmd);
    TCLAP::ValueArg<std::string> argTraj(
        "", "trajectory", "draw this TUM trajectory (optical frame, same world as the map)", false,
        "", "TRAJ.txt", cmd);
    TCLAP::ValueArg<double> argAzimuth("", "azimuth",
                                       "view azimuth around the vertical axis in degrees (180 = "
                                       "from behind the first camera)",
                                       false, RenderOptions{}.azimuthDeg, "DEG", cmd);
    TCLAP::ValueArg<double> argElevation("", "elevation", "view elevation in degrees (-90..90)",
                                         false, RenderOptions{}.elevationDeg, "DEG", cmd);
    TCLAP::ValueArg<double> argDistance(
        "", "distance", "camera distance from the map centre in metres (default: fit the map)",
        false, 0, "M", cmd);
    TCLAP::ValueArg<double> argPointSize("", "point-size", "point size in pixels", false,
                                         RenderOptions{}.pointSize, "N", cmd);
    TCLAP::ValueArg<double> argVoxel("", "voxel",
                                     "voxel size of the dense cloud in metres (0 = no filter)",
                                     false, DenseOptions{}.voxelSize, "M", cmd);
    TCLAP::ValueArg<int> argStride("", "stride", "use every N-th depth pixel of the keyframes",
                                   false, DenseOptions{}.pixelStride, "N", cmd);
    TCLAP::SwitchArg argNoFrustums("", "no-frustums", "do not draw the keyframes", cmd);
    TCLAP::SwitchArg argNoEdges("", "no-edges", "do not draw the graph edges", cmd);
    TCLAP::SwitchArg argQuiet("q", "quiet", "print nothing on success", cmd);
    if (auto rc = parseCommandLine(cmd, argc, argv, tool)) return *rc;

    RenderOptions render;
    render.width = argWidth.getValue();
    render.height = argHeight.getValue();
    render.azimuthDeg = argAzimuth.getValue();
    render.elevationDeg = argElevation.getValue();
    render.distance = argDistance.getValue();
    render.pointSize = argPointSize.getValue();
    render.showFrustums = !argNoFrustums.getValue();
    render.showEdges = !argNoEdges.getValue();
    render.validate();  // before any slow loading: a bad size is reported at once
    DenseOptions cloud;
    cloud.voxelSize = argVoxel.getValue();
    cloud.pixelStride = argStride.getValue();
    cloud.validate();

    const auto t0 = std::chrono::steady_clock::now();
    const std::string& mapPath = argMap.getValue();
    rejectPathClashes({{"MAP", mapPath}, {"--trajectory", argTraj.getValue()}},
                      {{"OUT", argOut.getValue()}, {"--scene", argScene.getValue()}});
    Trajectory trajectory;
    if (argTraj.isSet()) trajectory = readTumTrajectory(argTraj.getValue());

    MapRenderSummary summary;
    const std::string ext = lowerExtension(mapPath);
    if (ext == ".ply" || ext == ".pcd") {
      if (!haveDenseFileOutputs())
        throw std::runtime_error("this build cannot read '" + mapPath +
                                 "' (built without SLAMDUNK_WITH_DENSE)");
      MapRenderer renderer(render);
      DenseCloud points = readPointCloud(mapPath);
      if (points.empty()) throw std::runtime_error("point cloud '" + mapPath + "' is empty");
      summary.cloudPoints = points.size();
      summary.denseCloud = true;
      renderer.setCloud(std::move(points));
      renderer.setTrajectory(trajectory);
      const auto scene = renderer.buildScene();
      renderer.renderPng(*scene, argOut.getValue());
      if (argScene.isSet()) MapRenderer::saveScene(*scene, argScene.getValue());
    } else {
      const auto map = CKeyframeGraphMap::loadFromFile(mapPath);
      if (!map || !map->graph() || map->graph()->keyframeCount() == 0)
        throw std::runtime_error("map file '" + mapPath + "' holds no keyframes");
      summary = renderKeyframeGraph(*map->graph(), trajectory, argOut.getValue(),
                                    argScene.getValue(), render, cloud);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!argQuiet.getValue()) {
      std::cout << tool << ": " << argOut.getValue() << " (" << render.width << "x" << render.height
                << "): " << summary.cloudPoints << (summary.denseCloud ? " dense" : " feature")
                << " points, " << summary.keyframes << " keyframes";
      if (!trajectory.empty()) std::cout << ", " << trajectory.size() << " trajectory poses";
      if (argScene.isSet()) std::cout << "; scene " << argScene.getValue();
      std::cout << " in " << seconds << " s\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 1;
  }
}
