// A robot application embedding SlamDunk live (slamdunk::live::LiveSlam), in its two usual
// shapes:
//   embed-live IN.rawlog          frames from a source LiveSlam runs (here a rawlog replayed in
//                                 real time; a camera's MRPT sensor works the same way), the
//                                 application polls the latest pose at its own rate (10 Hz)
//   embed-live IN.rawlog --push   the application owns the frames (its driver, a ROS callback)
//                                 and pushes them; every pose comes back through a callback
// Either way it prints poses in both conventions and the session's outputs at the end.

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/live/LiveSlam.h>
#include <slamdunk/live/PushFrameSource.h>
#include <slamdunk/live/ReplayFrameSource.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

using namespace slamdunk::live;

namespace {

void printPose(const char* how, const LivePose& p) {
  const auto t = p.optical.translation();
  std::printf(
      "%s pose t=%.3f %-7s optical [%.3f %.3f %.3f] mrpt-sensor [x=%.3f y=%.3f z=%.3f "
      "yaw=%.1f deg]\n",
      how, p.timestamp, slamdunk::toString(p.status), t.x(), t.y(), t.z(), p.sensor.x(),
      p.sensor.y(), p.sensor.z(), p.sensor.yaw() * 180 / 3.14159265358979);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || (argc == 3 && std::strcmp(argv[2], "--push") != 0) || argc > 3) {
    std::fprintf(stderr, "usage: embed-live IN.rawlog [--push]\n");
    return 1;
  }
  const std::string rawlog = argv[1];
  const bool push = argc == 3;
  try {
    // Options in code (LiveSlam::fromIniFile("live.ini") reads them and the source instead).
    LiveOptions options;
    options.checkpoint.everyKeyframes = 0;  // no checkpoints: this example writes nothing
    options.checkpoint.everySeconds = 0;

    if (!push) {
      // LiveSlam's grabber thread reads the source; the application polls.
      LiveSlam live(options, std::make_unique<ReplayFrameSource>(rawlog, 1.0));
      live.start();
      if (!live.waitUntilOpen(10)) throw std::runtime_error("the source did not open");
      while (!live.finished()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        if (const LivePose p = live.latestPose(); p.valid) printPose("polled", p);
      }
      const LiveResult result = live.finish();
      std::printf("done: %zu frames tracked, %zu dropped, %zu keyframes\n", result.counters.tracked,
                  result.counters.dropped, result.stats.keyframes);
      return 0;
    }

    // The application's own frames, pushed; poses come back on the tracking thread.
    auto source = std::make_unique<PushFrameSource>();
    PushFrameSource& frames = *source;
    LiveSlam live(options, std::move(source));
    live.onPose([](const LivePose& p) {
      if (p.frameIndex % 10 == 0) printPose("callback", p);  // keep callbacks short
    });
    live.start();
    slamdunk::RawlogReader reader(rawlog);  // stands in for the robot's camera driver
    while (auto obs = reader.next()) {
      frames.push(obs);
      std::this_thread::sleep_for(std::chrono::milliseconds(33));  // a 30 Hz camera
    }
    frames.close();
    while (!live.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    const LiveResult result = live.finish();
    std::printf("done: %zu frames tracked, %zu dropped, %zu keyframes\n", result.counters.tracked,
                result.counters.dropped, result.stats.keyframes);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "embed-live: error: %s\n", e.what());
    return 1;
  }
}
