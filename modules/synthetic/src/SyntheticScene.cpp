#include <slamdunk/synthetic/SyntheticScene.h>

#include <mrpt/img/CImage.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/CSetOfTexturedTriangles.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

namespace slamdunk {

namespace {

using mrpt::math::TPoint3Df;

/// A set whose members are always drawn, never culled. MRPT 2.5 culls an object when none of its
/// bounding box's corners projects into the view, unless the corners lie in quadrants its table
/// pairs as "crossing the view". That table misses some pairs, so a large wall or floor seen from
/// inside the room, with every corner outside the view, is sometimes dropped whole: the scan's
/// frames 1099-1103 lost most of their walls and floor that way. A room's surfaces are few; the
/// GPU's own clipping is exact, so drawing them all costs little and is always right.
class UnculledSetOfObjects : public mrpt::opengl::CSetOfObjects {
 public:
  void enqueueForRenderRecursive(const mrpt::opengl::TRenderMatrices& state,
                                 mrpt::opengl::RenderQueue& rq,
                                 [[maybe_unused]] bool wholeInView) const override {
    mrpt::opengl::CSetOfObjects::enqueueForRenderRecursive(state, rq, /*wholeInView=*/true);
  }
};

// Every random draw is a statement of its own (or inside a braced list, which is evaluated left
// to right): C++ leaves the order of function arguments unspecified, and the textures must not
// depend on the compiler.

cv::Scalar randomColour(cv::RNG& rng) {
  // Independent channels over the full range: neighbouring shapes differ strongly in both
  // brightness and hue, which is what corner and blob detectors respond to.
  const double b = rng.uniform(0, 256), g = rng.uniform(0, 256), r = rng.uniform(0, 256);
  return {b, g, r};
}

cv::Point randomPoint(cv::RNG& rng, int w, int h) {
  const int x = rng.uniform(0, w), y = rng.uniform(0, h);
  return {x, y};
}

void drawRotatedRect(cv::Mat& img, cv::RNG& rng, int minSize, int maxSize) {
  const cv::Point2f c = randomPoint(rng, img.cols, img.rows);
  const float sx = float(rng.uniform(minSize, maxSize)), sy = float(rng.uniform(minSize, maxSize));
  // Mostly axis-aligned (like posters and tiles) but some rotated ones too.
  const float angle = rng.uniform(0, 3) == 0 ? rng.uniform(0.f, 180.f) : 0.f;
  const bool filled = rng.uniform(0, 4) > 0;
  const int thickness = rng.uniform(1, 4);
  const cv::Scalar colour = randomColour(rng);
  cv::Point2f corners[4];
  cv::RotatedRect(c, cv::Size2f(sx, sy), angle).points(corners);
  std::vector<cv::Point> poly(corners, corners + 4);
  if (filled)
    cv::fillConvexPoly(img, poly, colour, cv::LINE_AA);
  else
    cv::polylines(img, poly, true, colour, thickness, cv::LINE_AA);
}

void drawEllipse(cv::Mat& img, cv::RNG& rng, int minSize, int maxSize) {
  const cv::Point c = randomPoint(rng, img.cols, img.rows);
  const int ax = rng.uniform(minSize, maxSize) / 2 + 1, ay = rng.uniform(minSize, maxSize) / 2 + 1;
  const int thickness = rng.uniform(0, 3) == 0 ? rng.uniform(1, 4) : cv::FILLED;
  const double angle = rng.uniform(0.0, 180.0);
  const cv::Scalar colour = randomColour(rng);
  cv::ellipse(img, c, cv::Size(ax, ay), angle, 0, 360, colour, thickness, cv::LINE_AA);
}

void drawLine(cv::Mat& img, cv::RNG& rng, int minLen, int maxLen) {
  const cv::Point a = randomPoint(rng, img.cols, img.rows);
  const double angle = rng.uniform(0.0, 2 * M_PI);
  const double len = rng.uniform(minLen, maxLen);
  const int thickness = rng.uniform(1, 5);
  const cv::Scalar colour = randomColour(rng);
  const cv::Point b(a.x + int(len * std::cos(angle)), a.y + int(len * std::sin(angle)));
  cv::line(img, a, b, colour, thickness, cv::LINE_AA);
}

void drawText(cv::Mat& img, cv::RNG& rng, double minScale, double maxScale) {
  static const std::array<int, 6> fonts = {
      cv::FONT_HERSHEY_SIMPLEX, cv::FONT_HERSHEY_PLAIN,   cv::FONT_HERSHEY_DUPLEX,
      cv::FONT_HERSHEY_COMPLEX, cv::FONT_HERSHEY_TRIPLEX, cv::FONT_HERSHEY_SCRIPT_SIMPLEX};
  static const char alphabet[] = "ABCDEFGHJKLMNPQRSTUVWXYZabdefghkmnqrt0123456789#%&@";
  std::string text;
  const int len = rng.uniform(2, 9);
  for (int i = 0; i < len; ++i) text += alphabet[rng.uniform(0, int(sizeof(alphabet) - 1))];
  const double scale = rng.uniform(minScale, maxScale);
  const cv::Point origin = randomPoint(rng, img.cols, img.rows);
  const int font = fonts[rng.uniform(0, int(fonts.size()))];
  const cv::Scalar colour = randomColour(rng);
  const int thickness = std::max(1, int(scale * rng.uniform(0.8, 2.5)));
  cv::putText(img, text, origin, font, scale, colour, thickness, cv::LINE_AA);
}

/// One textured rectangle: p00..p01 get texture coordinates (0,0), (1,0), (1,1), (0,1), with
/// u along the image columns and v along the rows.
void addQuad(mrpt::opengl::CSetOfTexturedTriangles& obj, const TPoint3Df& p00, const TPoint3Df& p10,
             const TPoint3Df& p11, const TPoint3Df& p01, float u0 = 0, float v0 = 0, float u1 = 1,
             float v1 = 1) {
  mrpt::opengl::TTriangle t1(p00, p10, p11), t2(p00, p11, p01);
  t1.u(0) = u0, t1.v(0) = v0, t1.u(1) = u1, t1.v(1) = v0, t1.u(2) = u1, t1.v(2) = v1;
  t2.u(0) = u0, t2.v(0) = v0, t2.u(1) = u1, t2.v(1) = v1, t2.u(2) = u0, t2.v(2) = v1;
  // The texture is multiplied by the vertex colour: white keeps it unchanged.
  t1.setColor(mrpt::img::TColor(255, 255, 255));
  t2.setColor(mrpt::img::TColor(255, 255, 255));
  obj.insertTriangle(t1);
  obj.insertTriangle(t2);
}

/// `texture` is shared, not copied: the textures of an office take about a gigabyte.
mrpt::opengl::CSetOfTexturedTriangles::Ptr texturedObject(const cv::Mat& texture) {
  auto obj = mrpt::opengl::CSetOfTexturedTriangles::Create();
  // Unlit: the colour of a surface point does not depend on the viewpoint (a Lambertian surface
  // under fixed light), so the same point looks the same in every frame.
  obj->enableLight(false);
  obj->enableTextureLinearInterpolation(true);
  obj->assignImage(mrpt::img::CImage(texture, mrpt::img::SHALLOW_COPY));
  return obj;
}

/// Texture size along a surface `length` metres long: the smallest power of two (MRPT pads
/// other sizes) with texels no larger than `metresPerTexel`, up to 8192 (28 m of wall).
int texelsFor(double length, double metresPerTexel) {
  int n = 64;
  while (n < 8192 && n * metresPerTexel < length) n *= 2;
  return n;
}

/// About 3 mm per texel on walls and floors, finer than a VGA pixel at the usual 1.5-3 m. The
/// ceiling is seen from further away and less often: half as fine is enough.
constexpr double kTexelMetres = 0.0035;
constexpr double kCeilingTexelMetres = 2 * kTexelMetres;

void addBox(mrpt::opengl::CSetOfObjects& scene, const RoomBox& box, const cv::Mat& atlas) {
  // Texture atlas of 3 x 2 cells, one per visible face (the bottom one is never seen).
  auto obj = texturedObject(atlas);
  const double c = std::cos(box.yawDeg * M_PI / 180), s = std::sin(box.yawDeg * M_PI / 180);
  const double hx = box.sizeX / 2, hz = box.sizeZ / 2;
  const float top = float(box.baseY - box.sizeY), bottom = float(box.baseY);
  // Rotation about the vertical (y) axis, as the optical frame's yaw.
  auto corner = [&](double lx, double lz, float y) {
    return TPoint3Df(float(box.x + c * lx + s * lz), y, float(box.z - s * lx + c * lz));
  };
  const std::array<std::array<double, 2>, 4> footprint = {
      {{-hx, -hz}, {hx, -hz}, {hx, hz}, {-hx, hz}}};
  int cell = 0;
  auto cellUV = [&](int k, float& u0, float& v0, float& u1, float& v1) {
    u0 = float(k % 3) / 3, u1 = u0 + 1.f / 3, v0 = float(k / 3) / 2, v1 = v0 + 0.5f;
  };
  float u0, v0, u1, v1;
  for (int i = 0; i < 4; ++i, ++cell) {  // side faces, texture upright
    const auto& a = footprint[i];
    const auto& b = footprint[(i + 1) % 4];
    cellUV(cell, u0, v0, u1, v1);
    addQuad(*obj, corner(a[0], a[1], top), corner(b[0], b[1], top), corner(b[0], b[1], bottom),
            corner(a[0], a[1], bottom), u0, v0, u1, v1);
  }
  cellUV(cell, u0, v0, u1, v1);
  addQuad(*obj, corner(-hx, hz, top), corner(hx, hz, top), corner(hx, -hz, top),
          corner(-hx, -hz, top), u0, v0, u1, v1);
  scene.insert(obj);
}

}  // namespace

cv::Mat SyntheticScene::makeTexture(int width, int height, uint64_t seed, double detail) {
  // cv::RNG is a fixed multiply-with-carry generator: the same seed gives the same texture on
  // every platform and run. Mix the seed so that nearby seeds give unrelated sequences.
  cv::RNG rng(seed * 0x9E3779B97F4A7C15ULL + 0x632BE59BD9B4E019ULL);
  const int w = width, h = height;

  // 1. Smooth background: a coarse random colour grid interpolated to full size (softer on a
  // surface of less detail, as paint is).
  cv::Mat coarse(std::max(2, h / 96), std::max(2, w / 96), CV_8UC3);
  const double spread = 97.5 * (1 - 0.7 * (1 - std::clamp(detail, 0.0, 1.0)));
  rng.fill(coarse, cv::RNG::UNIFORM, 127.5 - spread, 127.5 + spread);
  cv::Mat tex;
  cv::resize(coarse, tex, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);

  // 2. Shapes at several scales; counts scale with the area so the density is the same on
  // every surface. Large shapes first so smaller ones land on top of them.
  const double area = double(w) * h * detail;
  const int unit = std::max(8, std::min(w, h) / 16);  // "large" shape size in texels
  for (int i = 0; i < int(area / 60000); ++i) drawRotatedRect(tex, rng, unit, 4 * unit);
  for (int i = 0; i < int(area / 60000); ++i) drawEllipse(tex, rng, unit, 3 * unit);
  for (int i = 0; i < int(area / 8000); ++i) drawRotatedRect(tex, rng, 8, 50);
  for (int i = 0; i < int(area / 8000); ++i) drawEllipse(tex, rng, 6, 40);
  for (int i = 0; i < int(area / 10000); ++i) drawLine(tex, rng, 20, 250);
  for (int i = 0; i < int(area / 15000); ++i) drawText(tex, rng, 0.6, 2.5);
  for (int i = 0; i < int(area / 2500); ++i) drawEllipse(tex, rng, 3, 10);

  // 3. Fine grain (like paper or fabric): low-amplitude noise, slightly blurred.
  cv::Mat noise(h, w, CV_16SC3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 14);
  cv::Mat grain;  // blurred into a new image: a blur in place copies its input first
  cv::GaussianBlur(noise, grain, cv::Size(0, 0), 0.8);
  cv::add(tex, grain, tex, cv::noArray(), CV_8U);  // summed wider, then saturated

  // 4. Mild low-pass: the renderer samples textures without mipmaps, so detail much finer than
  // a pixel would alias (flicker) between frames.
  cv::Mat smoothed;
  cv::GaussianBlur(tex, smoothed, cv::Size(0, 0), 0.7);
  return smoothed;
}

SyntheticScene::~SyntheticScene() = default;

SyntheticScene::SyntheticScene(unsigned seed, bool withCeiling)
    : SyntheticScene(FloorPlan::room(), seed, withCeiling) {}

SyntheticScene::SyntheticScene(FloorPlan plan, unsigned seed, bool withCeiling)
    : plan_(std::move(plan)), scene_(mrpt::opengl::COpenGLScene::Create()) {
  scene_->getViewport()->setCustomBackgroundColor(mrpt::img::TColorf(0, 0, 0));
  auto surfaces = std::make_shared<UnculledSetOfObjects>();
  scene_->insert(surfaces);
  auto& scene = *surfaces;
  uint64_t textureId = uint64_t(seed) << 16;  // one texture seed per surface

  const float yf = float(plan_.floorY), yc = float(plan_.ceilingY);
  const int wallTexelsHigh = texelsFor(plan_.floorY - plan_.ceilingY, kTexelMetres);
  // Walls: texture rows run downwards (+y) and columns to the right as seen from the free
  // space, so text on the walls reads normally.
  // A surface that repeats another's texture still takes its own seed, so that the surfaces
  // after it keep theirs.
  const uint64_t firstWall = textureId + 1;
  for (const auto& w : plan_.walls) {
    ++textureId;
    const uint64_t seedOfWall = w.textureOf >= 0 ? firstWall + uint64_t(w.textureOf) : textureId;
    auto obj = texturedObject(makeTexture(texelsFor(w.length(), kTexelMetres), wallTexelsHigh,
                                          seedOfWall, w.textureDetail));
    const TPoint3Df topLeft(float(w.x0), yc, float(w.z0)), topRight(float(w.x1), yc, float(w.z1));
    addQuad(*obj, topLeft, topRight, {topRight.x, yf, topRight.z}, {topLeft.x, yf, topLeft.z});
    scene.insert(obj);
  }
  // Floors and ceilings: texture columns along +x; rows along -z on the floor, +z above.
  auto areaTexture = [&](const FloorArea& a, double metresPerTexel) {
    return makeTexture(texelsFor(a.xMax - a.xMin, metresPerTexel),
                       texelsFor(a.zMax - a.zMin, metresPerTexel), ++textureId, a.textureDetail);
  };
  for (const auto& a : plan_.areas) {
    const float x0 = float(a.xMin), x1 = float(a.xMax), z0 = float(a.zMin), z1 = float(a.zMax);
    auto floor = texturedObject(areaTexture(a, kTexelMetres));
    addQuad(*floor, {x0, yf, z1}, {x1, yf, z1}, {x1, yf, z0}, {x0, yf, z0});
    scene.insert(floor);
  }
  if (withCeiling) {
    for (const auto& a : plan_.areas) {
      const float x0 = float(a.xMin), x1 = float(a.xMax), z0 = float(a.zMin), z1 = float(a.zMax);
      auto ceiling = texturedObject(areaTexture(a, kCeilingTexelMetres));
      addQuad(*ceiling, {x0, yc, z0}, {x1, yc, z0}, {x1, yc, z1}, {x0, yc, z1});
      scene.insert(ceiling);
    }
  }

  const uint64_t firstBox = textureId + 1;
  for (const auto& box : plan_.boxes) {
    ++textureId;
    const uint64_t seedOfBox = box.textureOf >= 0 ? firstBox + uint64_t(box.textureOf) : textureId;
    addBox(scene, box, makeTexture(1024, 512, seedOfBox));
  }
}

}  // namespace slamdunk
