// readExr / writeExr / writeExrChannels: round trips, the shipped maps, and every
// kind of bad input giving an InputError that names the file and the problem.
#include <Imath/half.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "Constants.h"
#include "Error.h"
#include "RawExr.h"
#include "scene/ExrIO.h"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using misalloc::InputError;
using misalloc::kPi;
using misalloc::readExr;
using misalloc::RgbImage;

namespace {

// A fresh folder for one test case, removed with its contents afterwards.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string& name)
      : path(fs::temp_directory_path() / ("misalloc_test_exr_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() { fs::remove_all(path); }
  std::string operator/(const std::string& file) const { return (path / file).string(); }
};

std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void writeBytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

RgbImage testImage(int width, int height) {
  RgbImage image{width, height, std::vector<float>(std::size_t(width) * height * 3)};
  // Distinct values of all magnitudes, each exactly representable as a half.
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = std::ldexp(float(i % 37 + 1), int(i % 11) - 5);
  return image;
}

// Writes `planes` (one per name, row 0 first) with OpenEXR directly, as HALF or FLOAT,
// over the data window (x0, y0)–(x0 + width − 1, y0 + height − 1), in `display` (the
// data window if empty).
void writeRawExr(const std::string& path, int width, int height, const std::vector<std::string>& names,
                 const std::vector<std::vector<float>>& planes, Imf::PixelType type, int x0 = 0, int y0 = 0,
                 Imath::Box2i display = Imath::Box2i()) {
  Imath::Box2i window({x0, y0}, {x0 + width - 1, y0 + height - 1});
  Imf::Header header(display.isEmpty() ? window : display, window);
  std::vector<std::vector<half>> halves(planes.size());
  Imf::FrameBuffer frame;
  for (std::size_t k = 0; k < names.size(); ++k) {
    header.channels().insert(names[k], Imf::Channel(type));
    halves[k].assign(planes[k].begin(), planes[k].end());
    const void* data = type == Imf::HALF ? (const void*)halves[k].data() : (const void*)planes[k].data();
    std::size_t bytes = type == Imf::HALF ? sizeof(half) : sizeof(float);
    frame.insert(names[k], Imf::Slice::Make(type, data, window, bytes, bytes * width));
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(height);
}

std::vector<std::vector<float>> planesOf(const RgbImage& image) {
  std::vector<std::vector<float>> planes(3, std::vector<float>(image.rgb.size() / 3));
  for (std::size_t p = 0; p < planes[0].size(); ++p)
    for (int c = 0; c < 3; ++c) planes[c][p] = image.rgb[3 * p + c];
  return planes;
}

std::string shippedMap(const std::string& name) { return std::string(MISALLOC_SOURCE_DIR) + "/data/envmaps/" + name; }

}  // namespace

TEST_CASE("writeExr and readExr round-trip float RGB exactly", "[exr]") {
  ScratchDir dir("float");
  RgbImage image = testImage(7, 5);
  image.rgb[4] = 3.0e38f;  // beyond the half range: the file must hold floats
  misalloc::writeExr(dir / "a.exr", image);
  RgbImage back = readExr(dir / "a.exr");
  CHECK(back.width == 7);
  CHECK(back.height == 5);
  CHECK(back.rgb == image.rgb);
  CHECK(back.alpha.empty());
  // With coverage, its alpha as channel A.
  image.alpha.assign(35, 1.0f);
  image.alpha[3] = 0.0f;
  misalloc::writeExr(dir / "b.exr", image);
  back = readExr(dir / "b.exr");
  CHECK(back.rgb == image.rgb);
  CHECK(back.alpha == image.alpha);
  CHECK(back.coveredPixels() == 34);
}

TEST_CASE("readExr reads half RGB and RGBA as float, alpha too, and honours the data window", "[exr]") {
  ScratchDir dir("half");
  RgbImage image = testImage(6, 4);
  auto planes = planesOf(image);
  SECTION("half RGB") { writeRawExr(dir / "h.exr", 6, 4, {"R", "G", "B"}, planes, Imf::HALF); }
  std::vector<float> alpha;
  SECTION("half RGBA") {
    alpha.assign(24, 0.5f);
    planes.push_back(alpha);
    writeRawExr(dir / "h.exr", 6, 4, {"R", "G", "B", "A"}, planes, Imf::HALF);
  }
  SECTION("float RGB, data window not at the origin") {
    writeRawExr(dir / "h.exr", 6, 4, {"R", "G", "B"}, planes, Imf::FLOAT, -3, 17);
  }
  RgbImage back = readExr(dir / "h.exr");
  CHECK(back.width == 6);
  CHECK(back.height == 4);
  CHECK(back.rgb == image.rgb);
  CHECK(back.alpha == alpha);
}

TEST_CASE("readExr places alpha with the data window, transparent outside it, and refuses alpha off [0, 1]", "[exr]") {
  ScratchDir dir("alpha");
  RgbImage data = testImage(3, 2);
  auto planes = planesOf(data);
  planes.push_back(std::vector<float>(6, 1.0f));
  writeRawExr(dir / "a.exr", 3, 2, {"R", "G", "B", "A"}, planes, Imf::FLOAT, 1, 1, Imath::Box2i({0, 0}, {4, 3}));
  RgbImage back = readExr(dir / "a.exr");
  REQUIRE(back.alpha.size() == 20);
  CHECK(back.coveredPixels() == 6);
  CHECK(back.alpha[0] == 0.0f);
  CHECK(back.alpha[1 * 5 + 1] == 1.0f);
  planes.back()[4] = 1.5f;
  writeRawExr(dir / "b.exr", 3, 2, {"R", "G", "B", "A"}, planes, Imf::FLOAT);
  CHECK_THROWS_WITH(readExr(dir / "b.exr"), Catch::Contains("its alpha at x=1, y=1 is 1.5"));
}

TEST_CASE("readExr places the data window in the display window, the texels outside it black", "[exr]") {
  // The lat-long mapping is the display window's: a map whose data covers part of it is
  // that part of the sphere, not a smaller sphere.
  ScratchDir dir("display");
  struct Case {
    Imath::Box2i display;
    int x0, y0, width, height;
  };
  const Case cases[] = {
      {Imath::Box2i({0, 0}, {63, 31}), 5, 3, 32, 16},   // inside
      {Imath::Box2i({0, 0}, {7, 3}), -2, -1, 12, 6},    // overscan: data beyond the display window
      {Imath::Box2i({10, 20}, {17, 23}), 12, 21, 3, 2}  // a display window not at the origin
  };
  for (const Case& c : cases) {
    RgbImage data = testImage(c.width, c.height);
    writeRawExr(dir / "w.exr", c.width, c.height, {"R", "G", "B"}, planesOf(data), Imf::FLOAT, c.x0, c.y0, c.display);
    RgbImage back = readExr(dir / "w.exr");
    const int W = c.display.max.x - c.display.min.x + 1, H = c.display.max.y - c.display.min.y + 1;
    REQUIRE(back.width == W);
    REQUIRE(back.height == H);
    int mismatches = 0, inData = 0;
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const int dx = x + c.display.min.x - c.x0, dy = y + c.display.min.y - c.y0;
        const bool covered = dx >= 0 && dx < c.width && dy >= 0 && dy < c.height;
        inData += covered;
        for (int ch = 0; ch < 3; ++ch) {
          const float expected = covered ? data.rgb[3 * (std::size_t(dy) * c.width + dx) + ch] : 0.0f;
          mismatches += back.rgb[3 * (std::size_t(y) * W + x) + ch] != expected;
        }
      }
    CHECK(inData > 0);
    CHECK(mismatches == 0);
  }
}

TEST_CASE("readExr reads the shipped maps as stats.json describes them", "[exr]") {
  std::ifstream statsFile(shippedMap("stats.json"));
  REQUIRE(statsFile);
  nlohmann::json stats = nlohmann::json::parse(statsFile);
  REQUIRE(stats.size() == 6);
  for (const auto& [name, expected] : stats.items()) {
    INFO(name);
    misalloc::ReadWarnings warnings;
    RgbImage image = readExr(shippedMap(name), &warnings);
    CHECK(image.width == expected["width"].get<int>());
    CHECK(image.height == expected["height"].get<int>());
    CHECK(warnings.negativeValues == expected["negative_pixels"].get<std::size_t>());
    float maxChannel = 0;
    for (float v : image.rgb) maxChannel = std::max(maxChannel, v);
    CHECK(maxChannel == expected["max_component"].get<float>());  // a stored value: exact
    // The solid-angle weighted mean luminance, with the exact texel solid angles.
    double power = 0;
    for (int row = 0; row < image.height; ++row) {
      double solidAngle =
          2 * kPi / image.width * (std::cos(kPi * row / image.height) - std::cos(kPi * (row + 1) / image.height));
      for (int col = 0; col < image.width; ++col) {
        const float* p = &image.rgb[3 * (std::size_t(row) * image.width + col)];
        power += misalloc::luminance(p[0], p[1], p[2]) * solidAngle;
      }
    }
    // Both sums are in double over the same float values; only their order differs,
    // by far less than this relative bound (N ε_double ≈ 6e-11 for 2^19 texels).
    CHECK(power / (4 * kPi) == Approx(expected["mean_sa"].get<double>()).epsilon(1e-9));
  }
}

TEST_CASE("readExr rejects bad files with an InputError naming the file and the problem", "[exr]") {
  ScratchDir dir("bad");
  misalloc::writeExr(dir / "good.exr", testImage(16, 8));
  std::string good = fileBytes(dir / "good.exr");

  auto requireError = [](const std::string& path, const std::string& words) {
    REQUIRE_THROWS_AS(readExr(path), InputError);
    REQUIRE_THROWS_WITH(readExr(path), Contains(path) && Contains(words));
  };

  SECTION("missing file") { requireError(dir / "absent.exr", "no such file"); }
  SECTION("not an EXR") {
    writeBytes(dir / "garbage.exr", "#?RADIANCE\nthis is not an OpenEXR file\n");
    requireError(dir / "garbage.exr", "not an OpenEXR file");
  }
  SECTION("empty file") {
    writeBytes(dir / "empty.exr", "");
    requireError(dir / "empty.exr", "not an OpenEXR file");
  }
  SECTION("truncated in the header") {
    writeBytes(dir / "cut.exr", good.substr(0, 40));
    requireError(dir / "cut.exr", "truncated or corrupt");
  }
  SECTION("truncated in the pixels") {
    writeBytes(dir / "cut.exr", good.substr(0, good.size() - 20));
    requireError(dir / "cut.exr", "truncated or corrupt");
  }
  SECTION("missing channel") {
    std::vector<float> plane(12, 1.0f);
    writeRawExr(dir / "rg.exr", 4, 3, {"R", "G"}, {plane, plane}, Imf::HALF);
    requireError(dir / "rg.exr", "no B channel");
    writeRawExr(dir / "y.exr", 4, 3, {"Y"}, {plane}, Imf::HALF);
    requireError(dir / "y.exr", "no R channel");
  }
  SECTION("empty data window") {
    // OpenEXR cannot write one; patch max.x of the dataWindow box2i below min.x.
    const std::string attribute("dataWindow\0box2i\0", 17);
    std::size_t at = good.find(attribute);
    REQUIRE(at != std::string::npos);
    std::string patched = good;
    int32_t maxX = -1;
    std::memcpy(&patched[at + attribute.size() + 4 + 8], &maxX, 4);  // after the size, min.x, min.y
    writeBytes(dir / "window.exr", patched);
    requireError(dir / "window.exr", "data window");
  }
  SECTION("NaN and infinite values") {
    RgbImage image = testImage(5, 4);
    image.rgb[3 * (1 * 5 + 2) + 1] = std::numeric_limits<float>::quiet_NaN();  // x=2, y=1, G
    image.rgb[3 * (3 * 5 + 0) + 2] = -std::numeric_limits<float>::infinity();
    misalloc::test::writeRawExr(dir / "nan.exr", image);
    requireError(dir / "nan.exr", "2 NaN or infinite channel values, the first at x=2, y=1, channel G");
  }
}

TEST_CASE("readExr sets negative values to 0 and reports them", "[exr]") {
  ScratchDir dir("negative");
  RgbImage image = testImage(5, 4);
  image.rgb[3 * (0 * 5 + 3) + 2] = -1.0f;  // x=3, y=0, B
  image.rgb[3 * (2 * 5 + 1) + 0] = -0.25f;
  image.rgb[3 * (3 * 5 + 4) + 1] = -0.0f;  // not negative radiance
  misalloc::writeExr(dir / "neg.exr", image);

  misalloc::ReadWarnings warnings;
  RgbImage back = readExr(dir / "neg.exr", &warnings);
  CHECK(warnings.negativeValues == 2);
  CHECK(warnings.firstNegative.x == 3);
  CHECK(warnings.firstNegative.y == 0);
  CHECK(warnings.firstNegative.channel == 'B');
  CHECK(misalloc::toString(warnings.firstNegative) == "x=3, y=0, channel B");
  for (std::size_t i = 0; i < image.rgb.size(); ++i) CHECK(back.rgb[i] == std::max(image.rgb[i], 0.0f));
  CHECK(readExr(dir / "neg.exr").rgb == back.rgb);  // the same without a warnings sink
}

TEST_CASE("writeExr replaces the target only when the whole file is written", "[exr]") {
  ScratchDir dir("write");
  const std::string target = dir / "out.exr";
  misalloc::writeExr(target, testImage(4, 2));
  const std::string before = fileBytes(target);

  SECTION("success replaces the target") {
    RgbImage other = testImage(3, 3);
    misalloc::writeExr(target, other);
    CHECK(readExr(target).rgb == other.rgb);
  }
  SECTION("a folder that does not exist") {
    const std::string nowhere = dir / "no/such/folder/out.exr";
    REQUIRE_THROWS_AS(misalloc::writeExr(nowhere, testImage(4, 2)), InputError);
    REQUIRE_THROWS_WITH(misalloc::writeExr(nowhere, testImage(4, 2)), Contains("cannot write") && Contains(nowhere));
    CHECK(fileBytes(target) == before);
  }
  SECTION("an existing target that cannot be replaced") {
    // A non-empty folder in the target's place: the temporary file is written in full,
    // then the rename fails (also for root, who may write into read-only folders).
    fs::create_directory(dir / "taken.exr");
    writeBytes(dir / "taken.exr/inside", "keep");
    REQUIRE_THROWS_AS(misalloc::writeExr(dir / "taken.exr", testImage(4, 2)), InputError);
    CHECK(fileBytes(dir / "taken.exr/inside") == "keep");
    CHECK(fileBytes(target) == before);
  }
  SECTION("an invalid image") {
    RgbImage broken = testImage(4, 2);
    broken.rgb.pop_back();
    REQUIRE_THROWS_AS(misalloc::writeExr(target, broken), std::invalid_argument);
    CHECK(fileBytes(target) == before);
  }
  // No temporary file is left behind, whatever happened.
  for (const auto& entry : fs::directory_iterator(dir.path))
    CHECK((entry.path().filename() == "out.exr" || entry.path().filename() == "taken.exr"));
}

TEST_CASE("writeExrChannels writes named float planes", "[exr]") {
  ScratchDir dir("channels");
  const int width = 5, height = 3;
  std::vector<std::string> names{"alpha.envmap", "alpha.brdf", "n"};
  std::vector<std::vector<float>> planes(3, std::vector<float>(width * height));
  for (int k = 0; k < 3; ++k)
    for (int p = 0; p < width * height; ++p) planes[k][p] = float(k) + float(p) / 64.0f;
  misalloc::writeExrChannels(dir / "alpha.exr", width, height, names, planes);

  Imf::InputFile file((dir / "alpha.exr").c_str());
  const Imath::Box2i& window = file.header().dataWindow();
  CHECK(window.max.x - window.min.x + 1 == width);
  CHECK(window.max.y - window.min.y + 1 == height);
  CHECK(file.header().compression() == Imf::ZIP_COMPRESSION);
  std::vector<std::vector<float>> back(3, std::vector<float>(width * height));
  Imf::FrameBuffer frame;
  for (int k = 0; k < 3; ++k) {
    const Imf::Channel* channel = file.header().channels().findChannel(names[k]);
    REQUIRE(channel);
    CHECK(channel->type == Imf::FLOAT);
    frame.insert(names[k], Imf::Slice::Make(Imf::FLOAT, back[k].data(), window));
  }
  file.setFrameBuffer(frame);
  file.readPixels(window.min.y, window.max.y);
  CHECK(back == planes);

  CHECK_THROWS_AS(misalloc::writeExrChannels(dir / "bad.exr", width, height, names, {planes[0]}),
                  std::invalid_argument);
  CHECK_THROWS_AS(misalloc::writeExrChannels(dir / "bad.exr", width, height, {"a", "a"}, {planes[0], planes[1]}),
                  std::invalid_argument);
  planes[2].pop_back();
  CHECK_THROWS_AS(misalloc::writeExrChannels(dir / "bad.exr", width, height, names, planes), std::invalid_argument);
  CHECK_FALSE(fs::exists(dir / "bad.exr"));
}
