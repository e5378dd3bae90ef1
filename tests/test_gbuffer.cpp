// G-buffers (scene/GBuffer.h): one physical scene written as each renderer writes it
// (the test writes the files) reads back as the same frames in the map's frame; each
// convention's turn of the map is checked against the renderer's own map formula; bad
// files are refused naming the problem.
#include <fmt/format.h>

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "Error.h"
#include "RawExr.h"
#include "SceneFixtures.h"
#include "VectorMath.h"
#include "scene/GBuffer.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

constexpr int kWidth = 8, kHeight = 6;
const Vec3d kCameraOrigin{1, 2, 3};  // in the map's frame

// The renderers' own lat-long lookups, written from their formulas (scene/GBuffer.h
// cites them): the direction each reads at (u, v).
Vec3d misallocDirection(double u, double v) {
  const double t = kPi * v, p = 2 * kPi * u;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}
Vec3d mitsubaDirection(double u, double v) {
  const double t = kPi * v, p = 2 * kPi * u;
  return {std::sin(p) * std::sin(t), std::cos(t), -std::cos(p) * std::sin(t)};
}
// Blender: u = (π − atan2(y, x))/2π, v = acos(z)/π.
Vec3d blenderDirection(double u, double v) {
  const double t = kPi * v, a = kPi - 2 * kPi * u;
  return {std::sin(t) * std::cos(a), std::sin(t) * std::sin(a), std::cos(t)};
}

// A direction of the map's frame in the convention's world: toMapFrame's inverse,
// written out.
Vec3d inWorld(GBufferConvention c, const Vec3d& m) {
  switch (c) {
    case GBufferConvention::Mitsuba:
      return {m[1], m[2], -m[0]};
    case GBufferConvention::Blender:
      return {-m[0], m[1], m[2]};
    default:
      return m;
  }
}

double distance(const Vec3d& a, const Vec3d& b) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// The scene: random frames in the map's frame, each pixel at a distance along its view
// from the camera; pixel 5 outside the alpha, pixel 7 with a zero normal; every third
// normal written facing away from the view (the reader turns it).
struct TruthScene {
  std::vector<PixelFrame> frames;
  std::vector<Vec3d> positions;
  std::vector<unsigned char> covered;
};

TruthScene truthScene() {
  Scene scene = smallScene("constant", "seed000", kWidth, kHeight);
  giveRandomFrames(scene, 11);
  TruthScene t{scene.geometry.pixels, {}, std::vector<unsigned char>(kWidth * kHeight, 1)};
  for (int p = 0; p < kWidth * kHeight; ++p) {
    const PixelFrame& f = t.frames[size_t(p)];
    // The view from the mirror direction: ω_o = 2(n·r)n − r.
    const Vec3f view = mirrorDirection(f.normal, f.mirror);
    const double d = 2 + 0.1 * p;
    t.positions.push_back(
        {kCameraOrigin[0] - d * view[0], kCameraOrigin[1] - d * view[1], kCameraOrigin[2] - d * view[2]});
  }
  t.covered[5] = t.covered[7] = 0;
  return t;
}

struct Written {
  std::vector<std::string> names;
  std::vector<std::vector<float>> planes;
};

// The scene's normals and positions in a convention's world, under channel prefixes.
Written inConvention(const TruthScene& t, GBufferConvention c, const std::string& normal, const std::string& position) {
  Written w{{normal + ".X", normal + ".Y", normal + ".Z", position + ".X", position + ".Y", position + ".Z", "A"},
            std::vector<std::vector<float>>(7, std::vector<float>(kWidth * kHeight))};
  for (int p = 0; p < kWidth * kHeight; ++p) {
    Vec3d n = inWorld(c, toDouble(t.frames[size_t(p)].normal));
    if (p % 3 == 0) n = {-n[0], -n[1], -n[2]};
    if (p == 7) n = {0, 0, 0};
    const Vec3d x = inWorld(c, t.positions[size_t(p)]);
    for (int k = 0; k < 3; ++k) w.planes[size_t(k)][size_t(p)] = float(n[size_t(k)]);
    for (int k = 0; k < 3; ++k) w.planes[size_t(3 + k)][size_t(p)] = float(x[size_t(k)]);
    w.planes[6][size_t(p)] = p == 5 ? 0.0f : 1.0f;
  }
  return w;
}

std::string originIn(GBufferConvention c) {
  const Vec3d o = inWorld(c, kCameraOrigin);
  return fmt::format("{},{},{}", o[0], o[1], o[2]);
}

// Every frame read matches the scene's within float rounding; the coverage exactly.
void checkFrames(const GBufferImage& read, const TruthScene& t) {
  REQUIRE(read.width == kWidth);
  REQUIRE(read.height == kHeight);
  CHECK(read.geometry.covered == t.covered);
  double worst = 0;
  for (size_t p = 0; p < t.frames.size(); ++p) {
    if (!t.covered[p]) continue;
    worst = std::max(worst, distance(toDouble(read.geometry.pixels[p].normal), toDouble(t.frames[p].normal)));
    worst = std::max(worst, distance(toDouble(read.geometry.pixels[p].mirror), toDouble(t.frames[p].mirror)));
  }
  CHECK(worst < 2e-5);
}

// Σ|a − b| / Σ|a| over two images of the same coverage.
double relativeDifference(const std::string& pathA, const std::string& pathB) {
  const RgbImage a = readExr(pathA), b = readExr(pathB);
  REQUIRE(a.alpha == b.alpha);
  double difference = 0, magnitude = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    difference += std::abs(a.rgb[i] - b.rgb[i]), magnitude += std::abs(a.rgb[i]);
  return difference / magnitude;
}

}  // namespace

TEST_CASE("each convention turns the renderer's lat-long lookup into misalloc's", "[gbuffer]") {
  for (double u : {0.0, 0.13, 0.25, 0.5, 0.8})
    for (double v : {0.1, 0.4, 0.5, 0.9}) {
      INFO(fmt::format("u {} v {}", u, v));
      const Vec3d expected = misallocDirection(u, v);
      CHECK(distance(toMapFrame(GBufferConvention::Mitsuba, mitsubaDirection(u, v)), expected) < 1e-12);
      CHECK(distance(toMapFrame(GBufferConvention::Blender, blenderDirection(u, v)), expected) < 1e-12);
      CHECK(distance(toMapFrame(GBufferConvention::Pbrt, expected), expected) == 0);
    }
  // The renderers' maps are turned against each other: no convention is another's.
  CHECK(distance(mitsubaDirection(0.13, 0.4), misallocDirection(0.13, 0.4)) > 0.1);
  CHECK(distance(blenderDirection(0.13, 0.4), misallocDirection(0.13, 0.4)) > 0.1);
}

TEST_CASE("one scene written as each renderer writes it reads back as the same frames", "[gbuffer]") {
  TempDir dir("gbuffer");
  const TruthScene truth = truthScene();
  struct Case {
    GBufferConvention convention;
    std::string name, normal, position;
  };
  const Case cases[] = {{GBufferConvention::Misalloc, "misalloc", "N", "P"},
                        {GBufferConvention::Mitsuba, "mitsuba", "sh_normal", "position"},
                        {GBufferConvention::Blender, "blender", "ViewLayer.Normal", "ViewLayer.Position"},
                        {GBufferConvention::Pbrt, "pbrt", "Ns", "P"}};
  for (const Case& c : cases) {
    INFO(c.name);
    const Written w = inConvention(truth, c.convention, c.normal, c.position);
    const std::string path = (dir.path / (c.name + ".exr")).string();
    writeRawChannels(path, kWidth, kHeight, w.names, w.planes);
    GBufferOptions options;
    options.path = path;
    options.convention = c.name;
    options.cameraOrigin = originIn(c.convention);
    if (c.convention == GBufferConvention::Pbrt) options.space = "world";
    checkFrames(readGBuffer(options), truth);
  }
  // Mitsuba's AOVs under the user's own names.
  const Written w = inConvention(truth, GBufferConvention::Mitsuba, "nn", "pos");
  const std::string path = (dir.path / "named.exr").string();
  writeRawChannels(path, kWidth, kHeight, w.names, w.planes);
  GBufferOptions options{path, "mitsuba", "nn", "pos", originIn(GBufferConvention::Mitsuba), ""};
  checkFrames(readGBuffer(options), truth);
}

TEST_CASE("pbrt's camera space reads through its header's worldToCamera", "[gbuffer]") {
  TempDir dir("gbuffer_pbrt");
  const TruthScene truth = truthScene();
  // A rotation about (1, 1, 1)/√3 by 40° with z flipped (pbrt's camera space is
  // left-handed), and the camera at kCameraOrigin: p_camera = R (p − o).
  const double a = 40 * kPi / 180, c = std::cos(a), s = std::sin(a), k = (1 - c) / 3, q = s / std::sqrt(3.0);
  const double rotation[3][3] = {{c + k, k - q, k + q}, {k + q, c + k, k - q}, {k - q, k + q, c + k}};
  double R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R[i][j] = (i == 2 ? -1 : 1) * rotation[i][j];
  std::array<float, 16> matrix{};
  for (int i = 0; i < 3; ++i) {
    double t = 0;
    for (int j = 0; j < 3; ++j) matrix[size_t(4 * i + j)] = float(R[i][j]), t -= R[i][j] * kCameraOrigin[size_t(j)];
    matrix[size_t(4 * i + 3)] = float(t);
  }
  matrix[15] = 1;
  Written w = inConvention(truth, GBufferConvention::Pbrt, "Ns", "P");
  for (size_t p = 0; p < size_t(kWidth * kHeight); ++p) {
    double n[3], x[3];
    for (int i = 0; i < 3; ++i) {
      n[i] = x[i] = 0;
      for (int j = 0; j < 3; ++j) {
        n[i] += R[i][j] * w.planes[size_t(j)][p];
        x[i] += R[i][j] * (w.planes[size_t(3 + j)][p] - kCameraOrigin[size_t(j)]);
      }
    }
    for (int i = 0; i < 3; ++i) w.planes[size_t(i)][p] = float(n[i]), w.planes[size_t(3 + i)][p] = float(x[i]);
  }
  const std::string path = (dir.path / "camera.exr").string();
  writeRawChannels(path, kWidth, kHeight, w.names, w.planes, {{"worldToCamera", matrix}});
  GBufferOptions options;
  options.path = path;
  options.convention = "pbrt";
  checkFrames(readGBuffer(options), truth);
  // The same file read as world space, seen from the camera its header places.
  options.space = "world";
  CHECK_NOTHROW(readGBuffer(options));
}

TEST_CASE("an orthographic G-buffer: normals and one view direction, no positions", "[gbuffer]") {
  TempDir dir("gbuffer_orthographic");
  // Random normals, every pixel seen along one direction (in the map's frame).
  TruthScene truth = truthScene();
  const double length = std::sqrt(0.98);
  const Vec3d view{0.3 / length, -0.5 / length, 0.8 / length};
  const Vec3f viewF{float(view[0]), float(view[1]), float(view[2])};
  for (PixelFrame& f : truth.frames) {
    if (f.normal[0] * viewF[0] + f.normal[1] * viewF[1] + f.normal[2] * viewF[2] < 0)
      for (float& x : f.normal) x = -x;
    f.mirror = mirrorDirection(f.normal, viewF);
  }
  for (GBufferConvention c : {GBufferConvention::Misalloc, GBufferConvention::Mitsuba, GBufferConvention::Blender}) {
    const std::string name = c == GBufferConvention::Misalloc  ? "misalloc"
                             : c == GBufferConvention::Mitsuba ? "mitsuba"
                                                               : "blender";
    INFO(name);
    const std::string normal = c == GBufferConvention::Misalloc  ? "N"
                               : c == GBufferConvention::Mitsuba ? "sh_normal"
                                                                 : "ViewLayer.Normal";
    Written w = inConvention(truth, c, normal, "unused");
    w.names.erase(w.names.begin() + 3, w.names.begin() + 6);  // no positions
    w.planes.erase(w.planes.begin() + 3, w.planes.begin() + 6);
    const std::string path = (dir.path / (name + ".exr")).string();
    writeRawChannels(path, kWidth, kHeight, w.names, w.planes);
    const Vec3d d = inWorld(c, view);
    GBufferOptions options;
    options.path = path;
    options.convention = name;
    options.viewDirection = fmt::format("{},{},{}", 2 * d[0], 2 * d[1], 2 * d[2]);  // any length
    checkFrames(readGBuffer(options), truth);
    options.cameraOrigin = originIn(c);
    CHECK_THROWS_WITH(readGBuffer(options), Catch::Contains("not both"));
    options.cameraOrigin.clear();
    options.viewDirection = "0,0,0";
    CHECK_THROWS_WITH(readGBuffer(options), Catch::Contains("non-zero length"));
    options.viewDirection = "1,nan,0";
    CHECK_THROWS_AS(readGBuffer(options), InputError);
  }
  const std::string out = (dir.path / "r.exr").string();
  auto r = runMisalloc("render --view-direction 0,0,1 --size 8x8 --spp 4 --no-preview --out " + out);
  INFO(r.output);
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--view-direction: the view of an orthographic G-buffer") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(out));
}

TEST_CASE("bad G-buffers are refused naming the problem", "[gbuffer][safety]") {
  TempDir dir("gbuffer_bad");
  const TruthScene truth = truthScene();
  auto write = [&](const std::string& name, Written w) {
    const std::string path = (dir.path / name).string();
    writeRawChannels(path, kWidth, kHeight, w.names, w.planes);
    return path;
  };
  const Written good = inConvention(truth, GBufferConvention::Misalloc, "N", "P");
  const std::string origin = originIn(GBufferConvention::Misalloc);
  auto read = [&](const std::string& path, const std::string& convention, const std::string& cameraOrigin,
                  const std::string& space = "") {
    return readGBuffer(GBufferOptions{path, convention, "", "", cameraOrigin, space});
  };
  const std::string goodPath = write("good.exr", good);
  CHECK_THROWS_WITH(read(goodPath, "mitsuba", origin),
                    Catch::Contains("has no channel sh_normal.X (looked for sh_normal.X, sh_normal.Y, sh_normal.Z; "
                                    "name others with --normal-channels; channels found: A, N.X"));
  CHECK_THROWS_WITH(read(goodPath, "blender", origin), Catch::Contains("no <ViewLayer>.Normal.X channel"));
  CHECK_THROWS_WITH(read(goodPath, "misalloc", ""), Catch::Contains("needs --camera-origin X,Y,Z"));
  CHECK_THROWS_WITH(read(goodPath, "misalloc", "1,2"), Catch::Contains("--camera-origin"));
  CHECK_THROWS_WITH(read(goodPath, "misalloc", origin, "camera"), Catch::Contains("only pbrt-v4 writes camera space"));
  CHECK_THROWS_WITH(read(goodPath, "maya", origin), Catch::Contains("--convention 'maya'"));
  CHECK_THROWS_WITH(read((dir.path / "none.exr").string(), "misalloc", origin), Catch::Contains("no such file"));
  const std::string pbrtPath = write("pbrt.exr", inConvention(truth, GBufferConvention::Pbrt, "Ns", "P"));
  CHECK_THROWS_WITH(read(pbrtPath, "pbrt", ""), Catch::Contains("no invertible worldToCamera"));
  Written nan = good;
  nan.planes[1][9] = std::nanf("");
  CHECK_THROWS_WITH(read(write("nan.exr", nan), "misalloc", origin),
                    Catch::Contains("the covered pixel at x=1, y=1 has a NaN or infinite normal or position"));
  Written onCamera = good;
  for (int k = 0; k < 3; ++k) onCamera.planes[size_t(3 + k)][4] = float(kCameraOrigin[size_t(k)]);
  CHECK_THROWS_WITH(read(write("camera.exr", onCamera), "misalloc", origin),
                    Catch::Contains("the camera lies on the surface the pixel at x=4, y=0 sees"));
  Written empty = good;
  std::fill(empty.planes[6].begin(), empty.planes[6].end(), 0.0f);
  CHECK_THROWS_WITH(read(write("empty.exr", empty), "misalloc", origin), Catch::Contains("covers no pixel"));
  Written layers = inConvention(truth, GBufferConvention::Blender, "A1.Normal", "A1.Position");
  Written second = inConvention(truth, GBufferConvention::Blender, "B2.Normal", "B2.Position");
  layers.names.insert(layers.names.end(), second.names.begin(), second.names.end() - 1);
  layers.planes.insert(layers.planes.end(), second.planes.begin(), second.planes.end() - 1);
  CHECK_THROWS_WITH(read(write("layers.exr", layers), "blender", origin),
                    Catch::Contains("several view layers (A1, B2)"));
}

// [release-only]: its reading is the unit tests' above, which the sanitizers run.
TEST_CASE("render --gbuffer: one scene as Mitsuba and as misalloc write it renders the same image",
          "[gbuffer][cli][release-only]") {
  TempDir dir("gbuffer_cli");
  const TruthScene truth = truthScene();
  std::vector<std::string> images;
  for (auto [convention, name, normal, position] :
       {std::tuple{GBufferConvention::Misalloc, "misalloc", "N", "P"},
        std::tuple{GBufferConvention::Mitsuba, "mitsuba", "sh_normal", "position"}}) {
    const Written w = inConvention(truth, convention, normal, position);
    const std::string gbuffer = (dir.path / fmt::format("{}.exr", name)).string();
    writeRawChannels(gbuffer, kWidth, kHeight, w.names, w.planes);
    const std::string out = (dir.path / fmt::format("{}-render.exr", name)).string();
    auto r =
        runMisalloc(fmt::format("render --gbuffer {} --convention {} --camera-origin {} --envmap sun --spp 64 "
                                "--method equal --device cpu --reference none --no-preview --out {} --report {}",
                                gbuffer, name, originIn(convention), out, (dir.path / "r.json").string()));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
    images.push_back(out);
    const nlohmann::json report = nlohmann::json::parse(std::ifstream(dir.path / "r.json"));
    CHECK(report["scene"]["covered_pixels"] == kWidth * kHeight - 2);
    CHECK(report["scene"]["envmap_pdf"]["used"] == "optimal-pixel");
  }
  // The same frames to float rounding, the same seed: the same image but where a sample
  // lands on another texel, far below the noise.
  CHECK(relativeDifference(images[0], images[1]) < 1e-3);
  // --view and --scene belong to the G-buffer, and its size to --size where given.
  auto r = runMisalloc(fmt::format("render --gbuffer {} --view 10 --camera-origin 1,2,3 --out {}",
                                   (dir.path / "misalloc.exr").string(), (dir.path / "x.exr").string()));
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--gbuffer with --view") != std::string::npos);
  r = runMisalloc(fmt::format("render --gbuffer {} --size 6x8 --camera-origin {} --out {}",
                              (dir.path / "misalloc.exr").string(), originIn(GBufferConvention::Misalloc),
                              (dir.path / "x.exr").string()));
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--size 6x8: the G-buffer") != std::string::npos);
  CHECK(r.output.find("is 8x6") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "x.exr"));
  // --grid beside a G-buffer that holds each pixel's BRDF.
  Written w = inConvention(truth, GBufferConvention::Misalloc, "N", "P");
  w.names.insert(w.names.end(), {"rho_d", "rho_s", "phong_n"});
  w.planes.resize(w.planes.size() + 3, std::vector<float>(size_t(kWidth * kHeight), 0.5f));
  const std::string brdf = (dir.path / "brdf.exr").string();
  writeRawChannels(brdf, kWidth, kHeight, w.names, w.planes);
  r = runMisalloc(fmt::format("render --gbuffer {} --camera-origin {} --grid seed000 --out {}", brdf,
                              originIn(GBufferConvention::Misalloc), (dir.path / "x.exr").string()));
  CHECK(r.exitCode == 2);
  CHECK(r.output.find("--grid with --gbuffer") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "x.exr"));
}

TEST_CASE("a G-buffer's BRDF channels give each pixel its BRDF, its UV channels lay the grid over it", "[gbuffer]") {
  TempDir dir("gbuffer_brdf");
  const TruthScene truth = truthScene();
  const size_t pixels = kWidth * kHeight;
  SceneOptions o;
  o.envmap = "constant";
  o.proceduralWidth = 64;
  o.gbuffer.convention = "misalloc";
  o.gbuffer.cameraOrigin = originIn(GBufferConvention::Misalloc);
  SECTION("BRDF channels") {
    Written w = inConvention(truth, GBufferConvention::Misalloc, "N", "P");
    w.names.insert(w.names.end(), {"rho_d", "rho_s", "phong_n"});
    w.planes.resize(w.planes.size() + 3, std::vector<float>(pixels));
    for (size_t p = 0; p < pixels; ++p) {
      w.planes[7][p] = 0.01f * float(p);
      w.planes[8][p] = 0.5f;
      w.planes[9][p] = p == 5 ? -1.0f : float(p);  // pixel 5 is background: not checked
    }
    o.gbuffer.path = (dir.path / "brdf.exr").string();
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    const Scene scene = makeScene(o);
    CHECK(scene.grid.spec == kGBufferBrdf);
    for (size_t p : {size_t(0), size_t(9), pixels - 1}) {
      INFO(p);
      CHECK(scene.grid.pixels[p].rhoD == w.planes[7][p]);
      CHECK(scene.grid.pixels[p].rhoS == 0.5f);
      CHECK(scene.grid.pixels[p].n == w.planes[9][p]);
    }
    // A covered pixel's BRDF that is none, and some channels without the others.
    w.planes[8][9] = 0.95f;
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    CHECK_THROWS_WITH(makeScene(o), Catch::Contains("the covered pixel at x=1, y=1 has rho_d 0.09, rho_s 0.95"));
    w.names.pop_back();
    w.planes.pop_back();
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    CHECK_THROWS_WITH(makeScene(o),
                      Catch::Contains("holds some of the BRDF channels rho_d, rho_s, phong_n but not all"));
  }
  SECTION("a roughness channel in the exponent's place") {
    Written w = inConvention(truth, GBufferConvention::Misalloc, "N", "P");
    w.names.insert(w.names.end(), {"rho_d", "rho_s", "roughness"});
    w.planes.resize(w.planes.size() + 3, std::vector<float>(pixels, 0.5f));
    w.planes[9][0] = 0.0f;
    w.planes[9][1] = 1.0f;
    w.planes[9][5] = 7.0f;  // pixel 5 is background: not checked
    o.gbuffer.path = (dir.path / "rough.exr").string();
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    const Scene scene = makeScene(o);
    CHECK(scene.grid.spec == kGBufferRoughnessBrdf);
    // r = 1/2: α = 1/4, α_p = 2·16 − 2 = 30, n = 30/4.
    CHECK(scene.grid.pixels[9].n == 7.5f);
    CHECK(scene.grid.pixels[0].n == 1e5f);
    CHECK(scene.grid.pixels[1].n == 0.0f);
    CHECK(scene.grid.pixels[9].rhoS == 0.5f);
    // A roughness outside [0, 1] on a covered pixel, and both exponents at once.
    w.planes[9][9] = std::nanf("");
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    CHECK_THROWS_WITH(makeScene(o), Catch::Contains("the covered pixel at x=1, y=1 has roughness nan, outside [0, 1]"));
    w.planes[9][9] = 0.5f;
    w.names.push_back("phong_n");
    w.planes.push_back(std::vector<float>(pixels, 10.0f));
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    CHECK_THROWS_WITH(makeScene(o), Catch::Contains("holds both phong_n and roughness"));
  }
  SECTION("UV channels") {
    Written w = inConvention(truth, GBufferConvention::Misalloc, "N", "P");
    w.names.insert(w.names.end(), {"uv.U", "uv.V"});
    w.planes.resize(w.planes.size() + 2, std::vector<float>(pixels));
    std::vector<SurfaceUv> uv;
    for (size_t p = 0; p < pixels; ++p) {
      w.planes[7][p] = 1.0f + 0.02f * float(p);  // wrapped into [0, 1)
      w.planes[8][p] = 0.5f - 0.01f * float(p);
      uv.push_back({double(w.planes[7][p]) - 1, double(w.planes[8][p])});
    }
    o.gbuffer.path = (dir.path / "uv.exr").string();
    writeRawChannels(o.gbuffer.path, kWidth, kHeight, w.names, w.planes);
    const Scene scene = makeScene(o);
    const BrdfGrid expected = makeBrdfGrid("seed000", kWidth, kHeight, uv);
    size_t mismatches = 0;
    for (size_t p = 0; p < pixels; ++p)
      mismatches += std::abs(scene.grid.pixels[p].rhoD - expected.pixels[p].rhoD) > 1e-6f ||
                    std::abs(scene.grid.pixels[p].n - expected.pixels[p].n) > 1e-4f * expected.pixels[p].n;
    CHECK(mismatches == 0);
  }
}

TEST_CASE("misalloc gbuffer writes a scene that render --gbuffer renders as the scene itself",
          "[gbuffer][cli][release-only]") {
  TempDir dir("gbuffer_round_trip");
  const std::string gbuffer = (dir.path / "g.exr").string();
  auto r = runMisalloc(fmt::format("gbuffer --scene spheres:2x2 --size 24x20 --out {}", gbuffer));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  std::vector<std::string> images;
  for (const std::string& scene :
       {fmt::format("--gbuffer {}", gbuffer), std::string("--scene spheres:2x2 --size 24x20")}) {
    images.push_back((dir.path / fmt::format("r{}.exr", images.size())).string());
    r =
        runMisalloc(fmt::format("render {} --envmap sun --spp 64 --method exact --cost 1,1.5 --device cpu --reference "
                                "none --no-preview --out {} --report {}",
                                scene, images.back(), (dir.path / "r.json").string()));
    INFO(r.output);
    REQUIRE(r.exitCode == 0);
  }
  // The view written and the mirror direction read back differ from the scene's by float
  // rounding only: the same image but where a sample lands on another texel.
  CHECK(relativeDifference(images[0], images[1]) < 1e-3);
  // It never replaces its own input.
  r = runMisalloc(fmt::format("gbuffer --gbuffer {0} --out {0}", gbuffer));
  CHECK(r.exitCode == 2);
}

// Independent of the mapping's derivation: the half-maximum angle of the Phong lobe about
// the mirror direction against that of the Beckmann distribution of half vectors at
// α = r², whose reflected directions turn twice as far. They agree as the lobe narrows.
TEST_CASE("a roughness's Phong lobe is as wide as its Beckmann microfacet distribution", "[gbuffer]") {
  for (double r : {0.05, 0.1, 0.2, 0.3, 0.4}) {
    const double a2 = r * r * r * r;
    auto beckmannOverPeak = [&](double t) {
      return std::exp(-std::tan(t) * std::tan(t) / a2) / std::pow(std::cos(t), 4) - 0.5;
    };
    double lo = 0, hi = 1.5;
    for (int i = 0; i < 200; ++i) (beckmannOverPeak(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
    const double halfVectorAngle = 0.5 * (lo + hi);
    const double n = phongExponentOfRoughness(r);
    const double lobeAngle = std::acos(std::pow(0.5, 1 / n));
    INFO("r = " << r << ", n = " << n);
    CHECK(lobeAngle == Approx(2 * halfVectorAngle).epsilon(0.02));
  }
}
