#include "scene/GBuffer.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <optional>

#include "Error.h"
#include "NumberList.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

using Vec = Eigen::Vector3d;

struct ChannelPrefixes {
  std::string normal, position;
};

// Blender names its passes by view layer: the one layer whose Normal pass the file holds.
std::string blenderViewLayer(const ExrHeader& header, const std::string& path) {
  std::vector<std::string> layers;
  const std::string suffix = ".Normal.X";
  for (const std::string& c : header.channels)
    if (c.size() > suffix.size() && c.compare(c.size() - suffix.size(), suffix.size(), suffix) == 0)
      layers.push_back(c.substr(0, c.size() - suffix.size()));
  if (layers.empty())
    throw InputError(fmt::format("'{}' has no <ViewLayer>.Normal.X channel, Blender's Normal pass (channels found: {})",
                                 path, fmt::join(header.channels, ", ")));
  if (layers.size() > 1)
    throw InputError(
        fmt::format("'{}' holds the Normal passes of several view layers ({}): name one with "
                    "--normal-channels and --position-channels",
                    path, fmt::join(layers, ", ")));
  return layers.front();
}

ChannelPrefixes channelPrefixes(GBufferConvention convention, const GBufferOptions& options, const ExrHeader& header) {
  ChannelPrefixes p;
  switch (convention) {
    case GBufferConvention::Misalloc:
      p = {"N", "P"};
      break;
    case GBufferConvention::Mitsuba:
      p = {"sh_normal", "position"};
      break;
    case GBufferConvention::Pbrt:
      p = {"Ns", "P"};
      break;
    case GBufferConvention::Blender:
      if (options.normalChannels.empty() || options.positionChannels.empty()) {
        const std::string layer = blenderViewLayer(header, options.path);
        p = {layer + ".Normal", layer + ".Position"};
      }
      break;
  }
  if (!options.normalChannels.empty()) p.normal = options.normalChannels;
  if (!options.positionChannels.empty()) p.position = options.positionChannels;
  return p;
}

// The channels a prefix names, or why the file lacks them.
std::vector<std::string> xyz(const std::string& prefix) { return {prefix + ".X", prefix + ".Y", prefix + ".Z"}; }

void requireChannels(const ExrHeader& header, const std::vector<std::string>& names, const std::string& path,
                     const std::string& option) {
  for (const std::string& n : names)
    if (std::find(header.channels.begin(), header.channels.end(), n) == header.channels.end())
      throw InputError(fmt::format("'{}' has no channel {} (looked for {}; name others with {}; channels found: {})",
                                   path, n, fmt::join(names, ", "), option, fmt::join(header.channels, ", ")));
}

const std::vector<std::string> kBrdfChannels{"rho_d", "rho_s", "phong_n"};
const std::vector<std::string> kRoughnessBrdfChannels{"rho_d", "rho_s", "roughness"};

// The planes `names` of a G-buffer in memory, whose header lists them (requireChannels).
std::vector<std::vector<float>> planesOf(const ChannelImage& image, const std::vector<std::string>& names) {
  std::vector<std::vector<float>> planes;
  for (const std::string& n : names) planes.push_back(image.planes.at(n));
  return planes;
}

bool hasChannel(const ExrHeader& header, const std::string& name) {
  return std::find(header.channels.begin(), header.channels.end(), name) != header.channels.end();
}

// The BRDF channels the file holds, all three or none: rho_d, rho_s and either the Phong
// exponent or a roughness.
std::vector<std::string> brdfChannels(const ExrHeader& header, const std::string& path) {
  if (hasChannel(header, "phong_n") && hasChannel(header, "roughness"))
    throw InputError(
        fmt::format("'{}' holds both phong_n and roughness, each of which would give the Phong exponent: "
                    "keep one (channels found: {})",
                    path, fmt::join(header.channels, ", ")));
  const std::vector<std::string>& names = hasChannel(header, "roughness") ? kRoughnessBrdfChannels : kBrdfChannels;
  const auto present =
      std::count_if(names.begin(), names.end(), [&](const std::string& c) { return hasChannel(header, c); });
  if (present > 0 && present < 3)
    throw InputError(fmt::format("'{}' holds some of the BRDF channels {} but not all (channels found: {})", path,
                                 fmt::join(names, ", "), fmt::join(header.channels, ", ")));
  return present == 3 ? names : std::vector<std::string>{};
}

// The convention's UV channels, where the file has them.
std::vector<std::string> uvChannels(GBufferConvention convention, const ChannelPrefixes& prefixes,
                                    const ExrHeader& header) {
  std::vector<std::string> names{"uv.U", "uv.V"};
  if (convention == GBufferConvention::Pbrt) names = {"u", "v"};
  if (convention == GBufferConvention::Blender) {
    const std::string layer = prefixes.normal.substr(0, prefixes.normal.rfind('.'));
    names = {layer + ".UV.U", layer + ".UV.V"};
  }
  return hasChannel(header, names[0]) && hasChannel(header, names[1]) ? names : std::vector<std::string>{};
}

void checkBrdf(const PhongParameters& b, const std::string& path, const std::string& where) {
  if (!(b.rhoD >= 0 && b.rhoS >= 0 && b.rhoD + b.rhoS <= 1 + 1e-6 && b.n >= 0 && b.n <= 1e5))
    throw InputError(
        fmt::format("'{}': the covered pixel at {} has rho_d {:g}, rho_s {:g}, phong_n {:g}: a BRDF needs "
                    "ρd, ρs ≥ 0, ρd + ρs ≤ 1 and n in [0, 1e5]",
                    path, where, b.rhoD, b.rhoS, b.n));
}

// The frames' way into the convention's world: camera space through the header's matrix.
struct WorldFromFile {
  std::optional<Eigen::Matrix4d> cameraFromWorld;  // camera space; none: world space
  std::optional<Vec> cameraOrigin;                 // world space: where each pixel is seen from
  std::optional<Vec> viewDirection;                // the file's space: every pixel's view (orthographic)
};

// --view-direction: a finite direction of non-zero length, in place of a camera origin.
std::optional<Vec> viewDirectionOf(const GBufferOptions& options) {
  if (options.viewDirection.empty()) return std::nullopt;
  if (!options.cameraOrigin.empty())
    throw InputError(
        "--view-direction with --camera-origin: an orthographic view (one direction) or a pinhole camera (a "
        "position), not both");
  const auto d = parseNumberList("--view-direction", options.viewDirection, options.viewDirection, 3, "expected X,Y,Z");
  const Vec direction(d[0], d[1], d[2]);
  if (!(direction.norm() > 0))
    throw InputError(fmt::format("--view-direction {}: a direction needs a non-zero length", options.viewDirection));
  return direction;
}

WorldFromFile worldFromFile(GBufferConvention convention, const GBufferOptions& options, const ExrHeader& header) {
  const std::string space =
      options.space.empty() ? (convention == GBufferConvention::Pbrt ? "camera" : "world") : options.space;
  if (space != "camera" && space != "world")
    throw InputError(fmt::format("--gbuffer-space '{}': expected camera or world", options.space));
  std::optional<Eigen::Matrix4d> matrix;
  if (auto it = header.matrices.find("worldToCamera"); it != header.matrices.end()) {
    matrix.emplace();
    for (int i = 0; i < 16; ++i) (*matrix)(i / 4, i % 4) = it->second[size_t(i)];
  }
  WorldFromFile out;
  out.viewDirection = viewDirectionOf(options);
  if (space == "camera") {
    if (convention != GBufferConvention::Pbrt)
      throw InputError("--gbuffer-space camera: only pbrt-v4 writes camera space (its header's worldToCamera)");
    if (!matrix || std::abs(matrix->topLeftCorner<3, 3>().determinant()) < 1e-12)
      throw InputError(
          fmt::format("'{}' has no invertible worldToCamera matrix in its header: a pbrt G-buffer in "
                      "camera space needs it (--gbuffer-space world if its scene says "
                      "coordinatesystem \"world\")",
                      options.path));
    if (!options.cameraOrigin.empty())
      throw InputError("--camera-origin with a pbrt G-buffer in camera space: its camera is at the origin");
    out.cameraFromWorld = matrix;
    return out;
  }
  if (out.viewDirection) return out;
  if (!options.cameraOrigin.empty()) {
    const auto o = parseNumberList("--camera-origin", options.cameraOrigin, options.cameraOrigin, 3, "expected X,Y,Z");
    out.cameraOrigin = Vec(o[0], o[1], o[2]);
  } else if (convention == GBufferConvention::Pbrt && matrix) {
    out.cameraOrigin = (matrix->inverse() * Eigen::Vector4d(0, 0, 0, 1)).head<3>();
  } else {
    throw InputError(
        fmt::format("--gbuffer {} with --convention {}: each pixel's view needs --camera-origin X,Y,Z "
                    "(the camera's position in the G-buffer's world) or, for an orthographic view, "
                    "--view-direction X,Y,Z",
                    options.path, options.convention));
  }
  return out;
}

Vec3f toFloat(const Vec& v) { return {float(v.x()), float(v.y()), float(v.z())}; }

Vec inMapFrame(GBufferConvention convention, const Vec& d) {
  const Vec3d m = toMapFrame(convention, {d.x(), d.y(), d.z()});
  return Vec(m[0], m[1], m[2]);
}

}  // namespace

// α = r² ([Bur12] Sec. 5.4) is the width of a Beckmann distribution of microfacet
// normals, which a Phong distribution of exponent α_p = 2/α² − 2 matches ([WMLT07]
// Sec. 5.2). misalloc's lobe is about the mirror direction, whose angle from it is twice
// the half vector's from the normal near the peak: cos^n(2θ) ≈ exp(−2nθ²) against
// cos^α_p(θ) ≈ exp(−α_p θ²/2), so n = α_p/4 = (1 − r⁴)/(2r⁴).
double phongExponentOfRoughness(double r) {
  constexpr double kMaxExponent = 1e5;
  const double r4 = r * r * r * r;
  return r4 * (2 * kMaxExponent + 1) <= 1 ? kMaxExponent : (1 - r4) / (2 * r4);
}

GBufferConvention parseGBufferConvention(const std::string& name) {
  if (name == "misalloc") return GBufferConvention::Misalloc;
  if (name == "mitsuba") return GBufferConvention::Mitsuba;
  if (name == "blender") return GBufferConvention::Blender;
  if (name == "pbrt") return GBufferConvention::Pbrt;
  throw InputError(fmt::format("--convention '{}': expected misalloc, mitsuba, blender or pbrt", name));
}

Vec3d toMapFrame(GBufferConvention convention, const Vec3d& d) {
  switch (convention) {
    case GBufferConvention::Mitsuba:
      return {-d[2], d[0], d[1]};
    case GBufferConvention::Blender:
      return {-d[0], d[1], d[2]};
    case GBufferConvention::Misalloc:
    case GBufferConvention::Pbrt:
      break;
  }
  return d;
}

GBufferImage readGBuffer(const GBufferOptions& options) {
  const GBufferConvention convention = parseGBufferConvention(options.convention);
  const ExrHeader header = options.channels ? options.channels->header : readExrHeader(options.path);
  const ChannelPrefixes prefixes = channelPrefixes(convention, options, header);
  const std::vector<std::string> normalNames = xyz(prefixes.normal), viewNames = xyz("view");
  const bool hasView =
      std::all_of(viewNames.begin(), viewNames.end(), [&](const std::string& c) { return hasChannel(header, c); });
  if (hasView && !options.viewDirection.empty())
    throw InputError(
        fmt::format("--view-direction: '{}' has view channels, which give each pixel's view", options.path));
  requireChannels(header, normalNames, options.path, "--normal-channels");
  const WorldFromFile world = hasView ? WorldFromFile{} : worldFromFile(convention, options, header);
  // The view channels are read in the positions' place; an orthographic view needs neither.
  const std::vector<std::string> positionNames =
      hasView ? viewNames : (world.viewDirection ? std::vector<std::string>{} : xyz(prefixes.position));
  requireChannels(header, positionNames, options.path, "--position-channels");
  std::vector<std::string> names = normalNames;
  names.insert(names.end(), positionNames.begin(), positionNames.end());
  const std::vector<std::string> brdfNames = brdfChannels(header, options.path);
  const bool hasAlpha = hasChannel(header, "A"), hasBrdf = !brdfNames.empty();
  const bool roughness = hasBrdf && brdfNames.back() == "roughness";
  const std::vector<std::string> uvNames =
      hasBrdf ? std::vector<std::string>{} : uvChannels(convention, prefixes, header);
  const size_t alphaPlane = names.size();
  if (hasAlpha) names.push_back("A");
  const size_t brdfPlane = names.size();
  names.insert(names.end(), brdfNames.begin(), brdfNames.end());
  const size_t uvPlane = names.size();
  names.insert(names.end(), uvNames.begin(), uvNames.end());
  const std::vector<std::vector<float>> planes =
      options.channels ? planesOf(*options.channels, names) : readExrChannels(options.path, names);

  GBufferImage out;
  out.width = header.width;
  out.height = header.height;
  const size_t pixels = size_t(out.width) * size_t(out.height);
  const Vec3f up{0.0f, 0.0f, 1.0f};
  out.geometry.pixels.assign(pixels, PixelFrame{up, up});
  out.geometry.covered.assign(pixels, 0);
  auto where = [&](size_t p) { return fmt::format("x={}, y={}", p % size_t(out.width), p / size_t(out.width)); };
  if (hasBrdf) {
    out.brdf.assign(pixels, PhongParameters{0, 0, 1});
    out.brdfSpec = roughness ? kGBufferRoughnessBrdf : kGBufferBrdf;
  }
  for (size_t p = 0; p < pixels && !uvNames.empty(); ++p) {
    const double u = planes[uvPlane][p], v = planes[uvPlane + 1][p];
    out.uv.push_back({std::isfinite(u) ? u - std::floor(u) : 0.0, std::isfinite(v) ? v - std::floor(v) : 0.0});
  }
  for (size_t p = 0; p < pixels; ++p) {
    const Vec n(planes[0][p], planes[1][p], planes[2][p]);
    const Vec position = positionNames.empty() ? Vec::Zero() : Vec(planes[3][p], planes[4][p], planes[5][p]);
    if (hasAlpha && !(planes[alphaPlane][p] > 0)) continue;
    if (n.x() == 0 && n.y() == 0 && n.z() == 0) continue;
    if (!n.allFinite() || !position.allFinite())
      throw InputError(fmt::format("'{}': the covered pixel at {} has a NaN or infinite normal or position",
                                   options.path, where(p)));
    Vec normal, view;
    if (hasView) {
      normal = n;
      view = position;  // the view channels, read in the positions' place
    } else if (world.cameraFromWorld) {
      // Normals by the inverse transpose of camera-from-world's inverse: its transpose.
      const Eigen::Matrix3d m = world.cameraFromWorld->topLeftCorner<3, 3>();
      normal = m.transpose() * n;
      view = m.inverse() * (world.viewDirection ? *world.viewDirection : Vec(-position));
    } else if (world.viewDirection) {
      normal = n;
      view = *world.viewDirection;
    } else {
      normal = n;
      view = *world.cameraOrigin - position;
    }
    if (!(view.norm() > 0))
      throw InputError(
          fmt::format("'{}': the camera lies on the surface the pixel at {} sees", options.path, where(p)));
    normal = inMapFrame(convention, normal).normalized();
    view = inMapFrame(convention, view).normalized();
    // Two-sided, as pbrt-v4's shading normals and Blender's Normal pass are.
    if (normal.dot(view) < 0) normal = -normal;
    const Vec3f nf = toFloat(normal);
    out.geometry.pixels[p] = PixelFrame{nf, mirrorDirection(nf, toFloat(view))};
    out.geometry.covered[p] = 1;
    if (hasBrdf) {
      float exponent = planes[brdfPlane + 2][p];
      if (roughness) {
        if (!(exponent >= 0 && exponent <= 1))
          throw InputError(fmt::format("'{}': the covered pixel at {} has roughness {:g}, outside [0, 1]", options.path,
                                       where(p), exponent));
        exponent = float(phongExponentOfRoughness(exponent));
      }
      out.brdf[p] = {planes[brdfPlane][p], planes[brdfPlane + 1][p], exponent};
      checkBrdf(out.brdf[p], options.path, where(p));
    }
  }
  if (out.geometry.coveredPixels() == 0)
    throw InputError(fmt::format("'{}' covers no pixel: every pixel has alpha 0 or a zero normal", options.path));
  return out;
}

std::string encodeGBuffer(int width, int height, const SceneGeometry& geometry,
                          const std::vector<PhongParameters>& brdf) {
  const std::vector<std::string> names{"N.X",    "N.Y", "N.Z",   "view.X", "view.Y",
                                       "view.Z", "A",   "rho_d", "rho_s",  "phong_n"};
  const size_t pixels = geometry.pixels.size();
  std::vector<std::vector<float>> planes(names.size(), std::vector<float>(pixels, 0.0f));
  for (size_t p = 0; p < pixels; ++p) {
    if (!geometry.covered[p]) continue;
    const PixelFrame& f = geometry.pixels[p];
    // The mirror direction's own mirror: the view.
    const Vec3f view = mirrorDirection(f.normal, f.mirror);
    const float values[] = {f.normal[0], f.normal[1], f.normal[2],  view[0],      view[1],
                            view[2],     1.0f,        brdf[p].rhoD, brdf[p].rhoS, brdf[p].n};
    for (size_t k = 0; k < names.size(); ++k) planes[k][p] = values[k];
  }
  return encodeExrChannels(width, height, names, planes);
}

}  // namespace misalloc
