// bench-features: times feature detection + description on the colour images of a TUM-layout
// folder (rgb.txt) for the project's SURF variants and, for comparison, OpenCV's ORB and SIFT.

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "slamdunk/features/Surf.h"

#include <slamdunk/core/CommandLine.h>
#include <slamdunk/core/Statistics.h>

namespace {

/// $SLAMDUNK_DATA_DIR/7scenes/seq-1000f, else the shared data folder seen from the project root.
std::string defaultFolder() {
  const char* dataDir = std::getenv("SLAMDUNK_DATA_DIR");
  const std::string base = dataDir && *dataDir ? dataDir : "../shared/data";
  return base + "/7scenes/seq-1000f";
}

struct Options {
  std::string folder = defaultFolder();
  int images = 20;
  int repeats = 3;
  double threshold = 500;
  int threads = -1;  // OpenCV default
  int orbFeatures = 1000;
};

void usage(const char* program) {
  std::cout << "Usage: " << program << " [options] [FOLDER]\n"
            << "  FOLDER           TUM-layout folder with rgb.txt (default " << Options().folder
            << ")\n"
            << "  -n, --images N   number of images to use (default 20)\n"
            << "  -r, --repeats R  passes over the images (default 3)\n"
            << "  -t, --threshold  SURF Hessian threshold (default 500)\n"
            << "  -j, --threads K  OpenCV worker threads (default: OpenCV's choice)\n"
            << "  --orb-features N ORB feature budget (default 1000)\n";
}

bool parse(int argc, char** argv, Options& opt) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> const char* {
      if (i + 1 >= argc) throw std::invalid_argument("missing value after " + arg);
      return argv[++i];
    };
    if (arg == "-h" || arg == "--help") {
      usage(argv[0]);
      std::exit(0);
    } else if (arg == "-n" || arg == "--images") {
      opt.images = std::atoi(value());
    } else if (arg == "-r" || arg == "--repeats") {
      opt.repeats = std::atoi(value());
    } else if (arg == "-t" || arg == "--threshold") {
      opt.threshold = std::atof(value());
    } else if (arg == "-j" || arg == "--threads") {
      opt.threads = std::atoi(value());
    } else if (arg == "--orb-features") {
      opt.orbFeatures = std::atoi(value());
    } else if (!arg.empty() && arg[0] == '-') {
      throw std::invalid_argument("unknown option " + arg);
    } else {
      opt.folder = arg;
    }
  }
  return opt.images > 0 && opt.repeats > 0;
}

/// The first `count` images listed in folder/rgb.txt ("timestamp filename", '#' comments), grey.
std::vector<cv::Mat> loadImages(const std::string& folder, int count) {
  std::ifstream list(folder + "/rgb.txt");
  if (!list) throw std::runtime_error("cannot open " + folder + "/rgb.txt");
  std::vector<cv::Mat> images;
  std::string line;
  while (static_cast<int>(images.size()) < count && std::getline(list, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string stamp, file;
    if (!(fields >> stamp >> file)) continue;
    cv::Mat grey = cv::imread(folder + "/" + file, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) throw std::runtime_error("cannot read " + folder + "/" + file);
    images.push_back(grey);
  }
  return images;
}

void benchmark(const std::string& name, const cv::Ptr<cv::Feature2D>& detector,
               const std::vector<cv::Mat>& images, int repeats) {
  std::vector<double> ms, cpuMs, counts;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  detector->detectAndCompute(images.front(), cv::noArray(), keypoints, descriptors);  // warm-up
  for (int r = 0; r < repeats; ++r) {
    for (const cv::Mat& image : images) {
      const std::clock_t cpuStart = std::clock();
      const auto start = std::chrono::steady_clock::now();
      detector->detectAndCompute(image, cv::noArray(), keypoints, descriptors);
      const auto stop = std::chrono::steady_clock::now();
      const std::clock_t cpuStop = std::clock();
      ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
      cpuMs.push_back(1000.0 * static_cast<double>(cpuStop - cpuStart) / CLOCKS_PER_SEC);
      if (r == 0) counts.push_back(static_cast<double>(keypoints.size()));
    }
  }
  const double mean = std::accumulate(ms.begin(), ms.end(), 0.0) / ms.size();
  std::printf("%-18s %10.2f %10.2f %10.2f %10.0f %6d\n", name.c_str(), slamdunk::median(ms), mean,
              slamdunk::median(cpuMs), slamdunk::median(counts), detector->descriptorSize());
}

}  // namespace

int main(int argc, char** argv) {
  return slamdunk::runTool("bench-features", [&] {
    Options opt;
    if (!parse(argc, argv, opt)) {
      usage(argv[0]);
      return 2;
    }
    if (opt.threads >= 0) cv::setNumThreads(opt.threads);
    const std::vector<cv::Mat> images = loadImages(opt.folder, opt.images);
    if (images.empty()) throw std::runtime_error("no images listed in " + opt.folder);
    std::printf("%zu images of %dx%d from %s, %d passes, %d OpenCV threads\n", images.size(),
                images[0].cols, images[0].rows, opt.folder.c_str(), opt.repeats,
                cv::getNumThreads());
    // Wall-clock times suffer when other processes compete for the cores; CPU time (all
    // threads of this process) shows the work itself.
    std::printf("%-18s %10s %10s %10s %10s %6s\n", "detector", "median ms", "mean ms", "cpu ms",
                "keypoints", "desc");

    const auto surf = [&](bool upright, bool extended) {
      slamdunk::Surf::Params p;
      p.hessianThreshold = opt.threshold;
      p.upright = upright;
      p.extended = extended;
      return slamdunk::Surf::create(p);
    };
    benchmark("SURF-64 upright", surf(true, false), images, opt.repeats);
    benchmark("SURF-64", surf(false, false), images, opt.repeats);
    benchmark("SURF-128", surf(false, true), images, opt.repeats);
    benchmark("ORB", cv::ORB::create(opt.orbFeatures), images, opt.repeats);
    benchmark("SIFT", cv::SIFT::create(), images, opt.repeats);
    return 0;
  });
}
