// A program that knows nothing of SlamDunk (it links MRPT only): it loads libslamdunk_mrpt_map.so
// as an MRPT plug-in and reads a saved keyframe map through MRPT's generic object factory, as
// RawLogViewer or SceneViewer3D would. Used by test_maps.
//
// Usage: slamdunk_map_plugin_reader PLUGIN.so|--no-plugin MAP_FILE
// Exit codes: 0 map read and not empty, 2 usage, 3 plug-in not loaded, 4 read failed,
// 5 not a CMetricMap / wrong class / empty map.

#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/maps/CMetricMap.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/system/os.h>

#include <iostream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: " << argv[0] << " PLUGIN.so|--no-plugin MAP_FILE\n";
    return 2;
  }
  const std::string plugin = argv[1], mapFile = argv[2];
  if (plugin != "--no-plugin") {
    std::string errors;
    if (!mrpt::system::loadPluginModule(plugin, errors)) {
      std::cerr << "cannot load plug-in '" << plugin << "': " << errors << "\n";
      return 3;
    }
  }
  mrpt::serialization::CSerializable::Ptr obj;
  try {
    mrpt::io::CFileGZInputStream f(mapFile);
    auto in = mrpt::serialization::archiveFrom(f);
    obj = in.ReadObject();
  } catch (const std::exception& e) {
    const std::string what = e.what();
    std::cerr << "cannot read '" << mapFile << "': " << what.substr(0, what.find('\n')) << "\n";
    return 4;
  }
  const std::string className = obj ? obj->GetRuntimeClass()->className : "(null)";
  std::cout << "class: " << className << "\n";
  const auto map = std::dynamic_pointer_cast<mrpt::maps::CMetricMap>(obj);
  if (!map) {
    std::cerr << "not a CMetricMap\n";
    return 5;
  }
  std::cout << "empty: " << (map->isEmpty() ? "yes" : "no") << "\n";
  std::cout << "asString: " << map->asString() << "\n";
  std::cout << "visualization objects: " << map->getVisualization()->size() << "\n";
  return className == "slamdunk::CKeyframeGraphMap" && !map->isEmpty() ? 0 : 5;
}
