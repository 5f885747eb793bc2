#include "edges/synth.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <set>
#include <unordered_map>

#include "core/error.h"
#include "core/hash.h"
#include "edges/feature_index.h"
#include "geometry/weld.h"

namespace glint::edges {
namespace {

using Vec = Eigen::Vector3d;
using Rng = std::mt19937_64;
constexpr double kPi = 3.14159265358979323846;
constexpr std::uint8_t kSharp = kLabelSharp, kBoundary = kLabelBoundary;

// Segments around a full circle: neighbouring facets differ by 3.75 degrees, far below any
// sensible sharp angle.
constexpr int kCircleSegments = 96;

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}
int uniform_int(Rng& rng, int low, int high) {
  return std::uniform_int_distribution<int>(low, high)(rng);
}
bool chance(Rng& rng, double probability) { return uniform(rng, 0.0, 1.0) < probability; }

struct Mesh {
  std::vector<Vec> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// A parametric surface f(u, v), u and v in [0, 1], as an nu x nv grid of quads. Seams and
// collapsed rows (poles, apexes, disc centres) are merged later by weld().
template <class Surface>
void add_surface(Mesh& mesh, int nu, int nv, Surface f) {
  const int first = static_cast<int>(mesh.vertices.size());
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) mesh.vertices.push_back(f(double(i) / nu, double(j) / nv));
  auto id = [&](int i, int j) { return first + j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
}

// Point at angle 2 pi u on the circle of radius r in the plane z. Every builder uses it, so
// rims of adjacent surfaces get bit-identical vertices.
Vec ring(double radius, double u, double z) {
  const double angle = 2.0 * kPi * u;
  return {radius * std::cos(angle), radius * std::sin(angle), z};
}

// Surface of a set of voxels scaled per axis; with skip_top the +z faces of the top layer
// stay open.
void add_voxels(Mesh& mesh, const std::set<std::array<int, 3>>& voxels, const Vec& scale,
                bool skip_top = false) {
  int top = 0;
  for (const auto& v : voxels) top = std::max(top, v[2]);
  for (const auto& v : voxels) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int side = 0; side < 2; ++side) {
        std::array<int, 3> neighbour = v;
        neighbour[axis] += side ? 1 : -1;
        if (voxels.count(neighbour)) continue;
        if (skip_top && axis == 2 && side == 1 && v[2] == top) continue;
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        Vec corner = Vec(v[0], v[1], v[2]);
        corner[axis] += side;
        Vec step_b = Vec::Zero(), step_c = Vec::Zero();
        step_b[b] = 1.0;
        step_c[c] = 1.0;
        add_surface(mesh, 1, 1, [&](double s, double t) -> Vec {
          return (corner + s * step_b + t * step_c).cwiseProduct(scale);
        });
      }
    }
  }
}

void add_disc(Mesh& mesh, double inner, double outer, double z) {
  add_surface(mesh, kCircleSegments, 1,
              [&](double u, double v) { return ring(inner + (outer - inner) * v, u, z); });
}

// ---- shapes, each in its own units (normalised afterwards).

// A strip folded along parallel lines: segment i leaves in a direction turned by angles[i-1]
// from the previous one (crease: sharp turns; bend: shallow ones).
void folded_strip(Mesh& mesh, Rng& rng, const std::vector<double>& turns) {
  const double width = uniform(rng, 0.5, 2.0);
  Vec start = Vec::Zero();
  double heading = 0.0;
  for (std::size_t i = 0; i <= turns.size(); ++i) {
    if (i > 0) heading += (chance(rng, 0.5) ? 1.0 : -1.0) * turns[i - 1];
    const Vec direction = uniform(rng, 0.4, 1.2) * Vec(std::cos(heading), 0.0, std::sin(heading));
    add_surface(mesh, 1, 1, [&](double u, double v) -> Vec {
      return start + u * direction + Vec(0.0, width * v, 0.0);
    });
    start += direction;
  }
}

std::set<std::array<int, 3>> fractal_voxels(Rng& rng) {
  const int size = uniform_int(rng, 3, 5);
  std::set<std::array<int, 3>> voxels;
  for (int x = 0; x < size; ++x)
    for (int y = 0; y < size; ++y)
      for (int z = 0; z < size; ++z) voxels.insert({x, y, z});
  const int edits = uniform_int(rng, 2, 10);
  for (int e = 0; e < edits; ++e) {
    std::array<int, 3> cell{uniform_int(rng, -1, size), uniform_int(rng, -1, size),
                            uniform_int(rng, -1, size)};
    int occupied_neighbours = 0;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = -1; side <= 1; side += 2) {
        std::array<int, 3> n = cell;
        n[axis] += side;
        occupied_neighbours += static_cast<int>(voxels.count(n));
      }
    // Bumps grow from a face; notches are cut where the voxel is exposed.
    if (!voxels.count(cell) && occupied_neighbours > 0)
      voxels.insert(cell);
    else if (voxels.count(cell) && occupied_neighbours < 6 && voxels.size() > 1)
      voxels.erase(cell);
  }
  return voxels;
}

std::set<std::array<int, 3>> stair_voxels(Rng& rng) {
  const int steps = uniform_int(rng, 2, 5), depth = uniform_int(rng, 1, 3);
  std::set<std::array<int, 3>> voxels;
  for (int i = 0; i < steps; ++i)
    for (int j = 0; j < depth; ++j)
      for (int k = 0; k <= i; ++k) voxels.insert({i, j, k});
  return voxels;
}

void add_holed_tiles(Mesh& mesh, Rng& rng) {
  const int tiles_x = uniform_int(rng, 1, 3), tiles_y = uniform_int(rng, 1, 3);
  constexpr int kPerSide = 16;
  for (int tx = 0; tx < tiles_x; ++tx)
    for (int ty = 0; ty < tiles_y; ++ty) {
      const double radius = chance(rng, 0.7) ? uniform(rng, 0.08, 0.4) : 0.0;
      const Vec centre(tx + 0.5, ty + 0.5, 0.0);
      // Ring from the hole's circle out to the tile's square; the square's vertices are the
      // same on both sides of a shared tile edge, so tiles weld into one sheet.
      add_surface(mesh, 4 * kPerSide, 2, [&](double u, double v) -> Vec {
        const double angle = kPi / 4.0 + 2.0 * kPi * u;
        const Vec direction(std::cos(angle), std::sin(angle), 0.0);
        const Vec square =
            0.5 * direction / std::max(std::abs(direction.x()), std::abs(direction.y()));
        return centre + radius * direction + v * (square - radius * direction);
      });
    }
}

struct Shape {
  Mesh mesh;
  nlohmann::json parameters = nlohmann::json::object();
};

Shape build_shape(SynthShape kind, Rng& rng, int points, double sharp_angle) {
  Shape shape;
  Mesh& mesh = shape.mesh;
  auto& p = shape.parameters;
  switch (kind) {
    case SynthShape::crease:
    case SynthShape::bend: {
      const int folds = uniform_int(rng, 1, 3);
      std::vector<double> turns;
      for (int i = 0; i < folds; ++i) {
        const double degrees = kind == SynthShape::crease ? uniform(rng, sharp_angle + 5.0, 160.0)
                                                          : uniform(rng, 0.0, sharp_angle - 8.0);
        turns.push_back(degrees * kPi / 180.0);
        p["turn_degrees"].push_back(degrees);
      }
      folded_strip(mesh, rng, turns);
      break;
    }
    case SynthShape::box:
    case SynthShape::open_box: {
      const Vec scale(1.0, uniform(rng, 0.3, 1.0), uniform(rng, 0.3, 1.0));
      add_voxels(mesh, {{0, 0, 0}}, scale, kind == SynthShape::open_box);
      p["size"] = {scale.x(), scale.y(), scale.z()};
      break;
    }
    case SynthShape::thin_wall: {
      // Thickness in point spacings of the two large faces.
      const double height = uniform(rng, 0.3, 1.0);
      const double spacings = uniform(rng, 1.0, 5.0);
      const double thickness = spacings * std::sqrt(2.0 * height / points);
      add_voxels(mesh, {{0, 0, 0}}, Vec(1.0, height, thickness));
      p["thickness_spacings"] = spacings;
      break;
    }
    case SynthShape::fractal_cube:
      add_voxels(mesh, fractal_voxels(rng), Vec::Ones());
      break;
    case SynthShape::stairs:
      add_voxels(mesh, stair_voxels(rng), Vec(1.0, uniform(rng, 0.7, 2.0), uniform(rng, 0.4, 1.2)));
      break;
    case SynthShape::cylinder:
    case SynthShape::tube:
    case SynthShape::cone:
    case SynthShape::frustum: {
      const double r0 = uniform(rng, 0.2, 0.6), height = uniform(rng, 0.3, 1.5);
      const double r1 = kind == SynthShape::cone      ? 0.0
                        : kind == SynthShape::frustum ? r0 * uniform(rng, 0.2, 0.8)
                                                      : r0;
      add_surface(mesh, kCircleSegments, 1,
                  [&](double u, double v) { return ring(r0 + (r1 - r0) * v, u, height * v); });
      if (kind != SynthShape::tube) add_disc(mesh, 0.0, r0, 0.0);
      if (kind == SynthShape::cylinder || kind == SynthShape::frustum)
        add_disc(mesh, 0.0, r1, height);
      p["radii"] = {r0, r1};
      p["height"] = height;
      break;
    }
    case SynthShape::sheet: {
      const double aspect = uniform(rng, 0.2, 1.0);
      add_surface(mesh, 1, 1, [&](double u, double v) { return Vec(u, aspect * v, 0.0); });
      break;
    }
    case SynthShape::wavy_sheet: {
      // Amplitude and frequency keep neighbouring facets within a few degrees.
      const double amplitude = uniform(rng, 0.02, 0.06), fu = uniform(rng, 0.5, 1.5),
                   fv = uniform(rng, 0.5, 1.5), phase = uniform(rng, 0.0, 2.0 * kPi);
      add_surface(mesh, 96, 96, [&](double u, double v) {
        return Vec(u, v,
                   amplitude * std::sin(2 * kPi * fu * u + phase) * std::cos(2 * kPi * fv * v));
      });
      p["amplitude"] = amplitude;
      break;
    }
    case SynthShape::disc:
    case SynthShape::annulus: {
      const double inner = kind == SynthShape::annulus ? uniform(rng, 0.15, 0.6) : 0.0;
      add_disc(mesh, inner, 1.0, 0.0);
      p["inner_radius"] = inner;
      break;
    }
    case SynthShape::holed_sheet:
      add_holed_tiles(mesh, rng);
      break;
    case SynthShape::sphere:
    case SynthShape::hemisphere: {
      const double extent = kind == SynthShape::sphere ? 1.0 : uniform(rng, 0.3, 0.7);
      const Vec axes(1.0, uniform(rng, 0.6, 1.0), uniform(rng, 0.6, 1.0));
      add_surface(mesh, kCircleSegments, kCircleSegments / 2, [&](double u, double v) -> Vec {
        const double polar = kPi * extent * v;
        return ring(std::sin(polar), u, -std::cos(polar)).cwiseProduct(axes);
      });
      p["polar_extent"] = extent;
      break;
    }
    case SynthShape::curved_sheet: {
      const double arc = uniform(rng, 60.0, 300.0), height = uniform(rng, 0.3, 1.5);
      add_surface(mesh, 64, 1,
                  [&](double u, double v) { return ring(0.5, u * arc / 360.0, height * v); });
      p["arc_degrees"] = arc;
      break;
    }
  }
  return shape;
}

// Merges coincident vertices and drops the triangles that collapse.
void weld(Mesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Vec& v : mesh.vertices) box.extend(v);
  geometry::weld_vertices(mesh, 1e-9 * std::max(box.diagonal().norm(), 1e-12));
}

Vec triangle_normal(const Mesh& mesh, const std::array<int, 3>& t) {
  const Vec& a = mesh.vertices[t[0]];
  return (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).normalized();
}

// Boundary edges (one face) and sharp edges (normals turning by at least the angle, or more
// than two faces). The normal of the second face is flipped when the two faces run along the
// edge in the same direction, so the test does not depend on how a builder wound its faces.
std::vector<FeatureSegment> feature_edges(const Mesh& mesh, double sharp_angle_deg) {
  struct Use {
    int triangle;
    bool forward;  // the triangle walks the edge from the lower to the higher vertex index
  };
  std::unordered_map<std::uint64_t, std::vector<Use>> edges;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int from = mesh.triangles[t][c], to = mesh.triangles[t][(c + 1) % 3];
      const auto key =
          (std::uint64_t(std::min(from, to)) << 32) | std::uint32_t(std::max(from, to));
      edges[key].push_back({static_cast<int>(t), from < to});
    }
  const double cos_sharp = std::cos(sharp_angle_deg * kPi / 180.0);
  std::vector<FeatureSegment> segments;
  for (const auto& [key, uses] : edges) {
    std::uint8_t label = 0;
    if (uses.size() == 1) {
      label = kBoundary;
    } else if (uses.size() > 2) {
      label = kSharp;
    } else {
      const Vec n0 = triangle_normal(mesh, mesh.triangles[uses[0].triangle]);
      Vec n1 = triangle_normal(mesh, mesh.triangles[uses[1].triangle]);
      if (uses[0].forward == uses[1].forward) n1 = -n1;
      if (n0.dot(n1) <= cos_sharp) label = kSharp;
    }
    if (label)
      segments.push_back({mesh.vertices[key >> 32], mesh.vertices[key & 0xffffffffu], label});
  }
  // The hash map's order depends on the library: sort for reproducible clouds.
  std::sort(segments.begin(), segments.end(), [](const FeatureSegment& l, const FeatureSegment& r) {
    return std::lexicographical_compare(l.a.data(), l.a.data() + 3, r.a.data(), r.a.data() + 3) ||
           (l.a == r.a &&
            std::lexicographical_compare(l.b.data(), l.b.data() + 3, r.b.data(), r.b.data() + 3));
  });
  return segments;
}

Eigen::Matrix3d random_rotation(Rng& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

// Centres the shape, scales its bounding-box diagonal to 1 and rotates it at random.
void place(Mesh& mesh, Rng& rng) {
  Eigen::AlignedBox3d box;
  for (const Vec& v : mesh.vertices) box.extend(v);
  const Eigen::Matrix3d rotation = random_rotation(rng);
  const double scale = 1.0 / box.diagonal().norm();
  for (Vec& v : mesh.vertices) v = rotation * ((v - box.center()) * scale);
}

}  // namespace

const std::vector<std::string>& synth_shape_names() {
  static const std::vector<std::string> names{
      "crease",   "bend",        "box",    "open_box",   "thin_wall",   "fractal_cube", "stairs",
      "cylinder", "tube",        "cone",   "frustum",    "sheet",       "wavy_sheet",   "disc",
      "annulus",  "holed_sheet", "sphere", "hemisphere", "curved_sheet"};
  return names;
}

SynthShape parse_synth_shape(const std::string& name) {
  const auto& names = synth_shape_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw Error("--shapes", name, fmt::format("unknown shape; known: {}", fmt::join(names, ", ")));
  return static_cast<SynthShape>(it - names.begin());
}

void check_synth_params(const SynthParams& p) {
  const std::string where = "synth parameters";
  if (p.min_points < 200 || p.max_points < p.min_points)
    throw Error(where, "points",
                fmt::format("need 200 <= min ({}) <= max ({})", p.min_points, p.max_points));
  if (p.noise_levels.empty()) throw Error(where, "noise", "give at least one noise level");
  for (double level : p.noise_levels)
    if (!(level >= 0.0 && level <= 5.0))
      throw Error(where, "noise", "levels must be in [0, 5] spacings");
  for (double probability : {p.outlier_probability, p.abc_probability, p.gradient_probability})
    if (!(probability >= 0.0 && probability <= 1.0))
      throw Error(where, "probability", "probabilities must be in [0, 1]");
  if (!(p.band > 0.0 && p.band <= 5.0)) throw Error(where, "band", "must be in (0, 5] spacings");
  if (!(p.boundary_band > 0.0 && p.boundary_band <= 5.0))
    throw Error(where, "boundary_band", "must be in (0, 5] spacings");
  if (!(p.sharp_angle_deg >= 10.0 && p.sharp_angle_deg <= 150.0))
    throw Error(where, "sharp_angle", "must be in [10, 150] degrees");
}

SynthCloud synthesize_cloud(const SynthParams& params, std::uint64_t index) {
  check_synth_params(params);
  Rng rng(mix64(params.seed ^ mix64(index)));
  const auto& all_names = synth_shape_names();
  const SynthShape kind =
      params.shapes.empty()
          ? static_cast<SynthShape>(uniform_int(rng, 0, static_cast<int>(all_names.size()) - 1))
          : params.shapes[uniform_int(rng, 0, static_cast<int>(params.shapes.size()) - 1)];
  const int points = static_cast<int>(std::lround(
      std::exp(uniform(rng, std::log(params.min_points), std::log(params.max_points)))));

  Shape shape = build_shape(kind, rng, points, params.sharp_angle_deg);
  Mesh& mesh = shape.mesh;
  weld(mesh);
  place(mesh, rng);
  const std::vector<FeatureSegment> features = feature_edges(mesh, params.sharp_angle_deg);

  std::vector<double> cumulative_area;
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Vec& a = mesh.vertices[t[0]];
    area += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
    cumulative_area.push_back(area);
  }
  const double spacing = std::sqrt(area / points);

  // Density weight in [1 - g, 1 + g] along a random direction; the local spacing scales with
  // 1 / sqrt(weight), and so does the label band.
  const bool has_gradient = chance(rng, params.gradient_probability);
  const double gradient = has_gradient ? uniform(rng, 0.3, 0.8) : 0.0;
  const Vec gradient_direction = random_rotation(rng).col(0);
  auto weight = [&](const Vec& p) {
    return 1.0 + gradient * std::clamp(2.0 * p.dot(gradient_direction), -1.0, 1.0);
  };
  auto local_spacing = [&](const Vec& p) { return spacing / std::sqrt(weight(p)); };
  const FeatureIndex index_of_features(
      features, std::max(params.band, params.boundary_band) * spacing / std::sqrt(1.0 - gradient));

  const bool abc = chance(rng, params.abc_probability);
  const double noise =
      params.noise_levels[uniform_int(rng, 0, int(params.noise_levels.size()) - 1)];
  const double outlier_share =
      chance(rng, params.outlier_probability) ? uniform(rng, 0.02, 0.15) : 0.0;

  std::vector<Vec> positions;
  positions.reserve(points);
  if (abc) {
    // Points exactly on the feature edges, about one spacing apart, as mesh vertices lie.
    for (const FeatureSegment& s : features) {
      const double step = spacing * uniform(rng, 0.7, 1.3);
      for (double t = uniform(rng, 0.0, step); t < (s.b - s.a).norm(); t += step)
        positions.push_back(s.a + (s.b - s.a).normalized() * t);
    }
    if (positions.size() > std::size_t(points) / 3) positions.resize(std::size_t(points) / 3);
  }
  while (positions.size() < std::size_t(points)) {
    const double pick = uniform(rng, 0.0, area);
    const auto t =
        mesh.triangles[std::lower_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
                       cumulative_area.begin()];
    double r1 = uniform(rng, 0.0, 1.0), r2 = uniform(rng, 0.0, 1.0);
    if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
    const Vec p = mesh.vertices[t[0]] + r1 * (mesh.vertices[t[1]] - mesh.vertices[t[0]]) +
                  r2 * (mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    if (has_gradient && uniform(rng, 0.0, 1.0 + gradient) > weight(p)) continue;
    positions.push_back(p);
  }

  PointCloud cloud;
  cloud.reserve(positions.size());
  std::vector<std::uint8_t> labels(positions.size());
  std::size_t counts[3] = {0, 0, 0}, outliers = 0;
  std::normal_distribution<double> normal;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    Vec p = positions[i];
    const double local = local_spacing(p);
    auto label_at = [&](const Vec& q) {
      return index_of_features.label(q, params.band * local, params.boundary_band * local);
    };
    std::uint8_t label = label_at(p);
    if (noise > 0.0) p += noise * spacing * Vec(normal(rng), normal(rng), normal(rng));
    if (outlier_share > 0.0 && chance(rng, outlier_share)) {
      // Displaced 2-15 spacings; labelled where it landed.
      p += uniform(rng, 2.0, 15.0) * spacing * random_rotation(rng).col(0);
      label = label_at(p);
      ++outliers;
    }
    cloud.push_back(float(p.x()), float(p.y()), float(p.z()));
    labels[i] = label;
    ++counts[label];
  }
  cloud.set("label", std::move(labels));

  SynthCloud result;
  result.cloud = std::move(cloud);
  result.description = {
      {"index", index},
      {"shape", all_names[static_cast<std::size_t>(kind)]},
      {"shape_parameters", shape.parameters},
      {"points", positions.size()},
      {"spacing", spacing},
      {"sampling", abc ? "abc" : "uniform"},
      {"density_gradient", gradient},
      {"noise_spacings", noise},
      {"outliers", outliers},
      {"labels", {{"non-edge", counts[0]}, {"sharp-edge", counts[1]}, {"boundary", counts[2]}}}};
  return result;
}

}  // namespace glint::edges
