#include "cad/sample.h"

#include <embree3/rtcore.h>
#include <fmt/format.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Eigen/Geometry>
#include <GCPnts_TangentialDeflection.hxx>
#include <Geom2d_Curve.hxx>
#include <Poly_Triangulation.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <unordered_map>

#include "cad/part.h"
#include "cad/surface_mesh.h"
#include "core/error.h"
#include "geometry/weld.h"

namespace glint::cad {
namespace {

using Vec = Eigen::Vector3d;
using Rng = std::mt19937_64;
constexpr double kPi = 3.14159265358979323846;

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}

Vec to_vec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

// Triangulates every face with BRepMesh (single-threaded, so the result is reproducible).
SurfaceMesh tessellate(const TopoDS_Shape& shape, double linear_deflection, double angular_rad) {
  BRepTools::Clean(shape);
  BRepMesh_IncrementalMesh mesher(shape, linear_deflection, false, angular_rad, false);
  if (!mesher.IsDone()) throw Error("tessellation", "", "BRepMesh_IncrementalMesh failed");
  SurfaceMesh mesh;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) {
    const TopoDS_Face face = TopoDS::Face(it.Current());
    TopLoc_Location location;
    const Handle(Poly_Triangulation) triangulation = BRep_Tool::Triangulation(face, location);
    if (triangulation.IsNull()) continue;
    const int first = static_cast<int>(mesh.vertices.size());
    for (int i = 1; i <= triangulation->NbNodes(); ++i)
      mesh.vertices.push_back(
          to_vec(triangulation->Node(i).Transformed(location.Transformation())));
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (int i = 1; i <= triangulation->NbTriangles(); ++i) {
      int a, b, c;
      triangulation->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      mesh.triangles.push_back({first + a - 1, first + b - 1, first + c - 1});
    }
  }
  if (mesh.triangles.empty()) throw Error("tessellation", "", "the shape has no meshable faces");
  return mesh;
}

// Splits triangles at the midpoint of their longest edge until no edge exceeds max_edge
// (a midpoint is shared by the triangles on both sides of its edge).
void refine(SurfaceMesh& mesh, double max_edge) {
  std::unordered_map<std::uint64_t, int> midpoints;
  std::vector<std::array<int, 3>> done, todo = std::move(mesh.triangles);
  while (!todo.empty()) {
    std::array<int, 3> t = todo.back();
    todo.pop_back();
    int longest = 0;
    double length = 0.0;
    for (int c = 0; c < 3; ++c) {
      const double l = (mesh.vertices[t[c]] - mesh.vertices[t[(c + 1) % 3]]).norm();
      if (l > length) length = l, longest = c;
    }
    if (length <= max_edge) {
      done.push_back(t);
      continue;
    }
    const int a = t[longest], b = t[(longest + 1) % 3], c = t[(longest + 2) % 3];
    auto [it, inserted] = midpoints.emplace(edge_key(a, b), static_cast<int>(mesh.vertices.size()));
    if (inserted) mesh.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
    todo.push_back({a, it->second, c});
    todo.push_back({it->second, b, c});
  }
  mesh.triangles = std::move(done);
}

struct Samples {
  std::vector<Vec> positions, normals;
  std::vector<double> spacing;         // local spacing at each sample
  std::vector<std::uint8_t> not_seen;  // scan: next to surface no viewpoint sees
  nlohmann::json description = nlohmann::json::object();
};

// Area-weighted random points on the triangles (normals are the triangles').
class SurfaceSampler {
 public:
  explicit SurfaceSampler(const SurfaceMesh& mesh) : mesh_(mesh) {
    for (const auto& t : mesh.triangles) {
      area_ += triangle_area(mesh, t);
      cumulative_.push_back(area_);
    }
  }
  double area() const { return area_; }
  void draw(Rng& rng, Vec& position, Vec& normal) const {
    const double pick = uniform(rng, 0.0, area_);
    const std::size_t index = std::min<std::size_t>(
        std::lower_bound(cumulative_.begin(), cumulative_.end(), pick) - cumulative_.begin(),
        cumulative_.size() - 1);
    const auto& t = mesh_.triangles[index];
    double r1 = uniform(rng, 0.0, 1.0), r2 = uniform(rng, 0.0, 1.0);
    if (r1 + r2 > 1.0) r1 = 1.0 - r1, r2 = 1.0 - r2;
    const Vec& a = mesh_.vertices[t[0]];
    position = a + r1 * (mesh_.vertices[t[1]] - a) + r2 * (mesh_.vertices[t[2]] - a);
    normal = triangle_normal(mesh_, t);
  }

 private:
  const SurfaceMesh& mesh_;
  std::vector<double> cumulative_;
  double area_ = 0.0;
};

// The vertices of a welded mesh (long edges split when plane_edge_fraction asks).
Samples sample_vertices(SurfaceMesh mesh, const SampleParams& p, double diagonal, Rng& rng) {
  if (p.plane_edge_fraction > 0.0) refine(mesh, p.plane_edge_fraction * diagonal);
  const std::size_t n = mesh.vertices.size();
  std::vector<Vec> normals(n, Vec::Zero());
  std::vector<double> edge_sum(n, 0.0);
  std::vector<int> edge_count(n, 0);
  for (const auto& t : mesh.triangles) {
    const Vec weighted = triangle_normal(mesh, t) * triangle_area(mesh, t);
    for (int c = 0; c < 3; ++c) {
      normals[t[c]] += weighted;
      const double l = (mesh.vertices[t[c]] - mesh.vertices[t[(c + 1) % 3]]).norm();
      edge_sum[t[c]] += l, edge_sum[t[(c + 1) % 3]] += l;
      ++edge_count[t[c]], ++edge_count[t[(c + 1) % 3]];
    }
  }
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < n; ++i)
    if (edge_count[i] > 0) kept.push_back(i);
  if (kept.size() > std::size_t(p.points)) {
    std::shuffle(kept.begin(), kept.end(), rng);
    kept.resize(std::size_t(p.points));
    std::sort(kept.begin(), kept.end());
  }
  Samples s;
  for (std::size_t i : kept) {
    s.positions.push_back(mesh.vertices[i]);
    s.normals.push_back(normals[i].norm() > 0 ? Vec(normals[i].normalized()) : Vec(0, 0, 1));
    s.spacing.push_back(edge_sum[i] / edge_count[i]);
  }
  s.description = {{"plane_edge_fraction", p.plane_edge_fraction},
                   {"mesh_vertices", n},
                   {"mesh_triangles", mesh.triangles.size()}};
  return s;
}

// A fine tessellation for uniform and scan sampling: chord error far below a point spacing.
SurfaceMesh fine_mesh(const TopoDS_Shape& shape, double diagonal) {
  return tessellate(shape, 2e-4 * diagonal, 8.0 * kPi / 180.0);
}

Samples sample_uniform(const SurfaceMesh& mesh, const SampleParams& p, Rng& rng) {
  const SurfaceSampler sampler(mesh);
  const double spacing = std::sqrt(sampler.area() / p.points);
  Samples s;
  s.positions.resize(p.points);
  s.normals.resize(p.points);
  s.spacing.assign(p.points, spacing);
  for (int i = 0; i < p.points; ++i) sampler.draw(rng, s.positions[i], s.normals[i]);
  s.description = {{"surface_area", sampler.area()}};
  return s;
}

// ---- scan sampling (Embree ray casts on the fine tessellation or the mesh).

class RayCaster {
 public:
  explicit RayCaster(const SurfaceMesh& mesh) {
    device_ = rtcNewDevice("threads=1");
    scene_ = rtcNewScene(device_);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.vertices.size()));
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = float(mesh.vertices[i][k]);
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), mesh.triangles.size()));
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) indices[3 * i + k] = unsigned(mesh.triangles[i][k]);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene_);
  }
  ~RayCaster() {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Distance to the first hit along the unit direction (infinity when none) and its normal.
  double cast(const Vec& origin, const Vec& direction, Vec* normal = nullptr) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit hit{};
    hit.ray.org_x = float(origin.x()), hit.ray.org_y = float(origin.y());
    hit.ray.org_z = float(origin.z());
    hit.ray.dir_x = float(direction.x()), hit.ray.dir_y = float(direction.y());
    hit.ray.dir_z = float(direction.z());
    hit.ray.tnear = 0.0f;
    hit.ray.tfar = std::numeric_limits<float>::infinity();
    hit.ray.mask = 0xffffffffu;
    hit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context, &hit);
    if (hit.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::numeric_limits<double>::infinity();
    if (normal) *normal = Vec(hit.hit.Ng_x, hit.hit.Ng_y, hit.hit.Ng_z).normalized();
    return hit.ray.tfar;
  }

 private:
  RTCDevice device_;
  RTCScene scene_;
};

struct Viewpoint {
  Vec position;
  Eigen::Matrix3d frame;  // columns: right, up, forward (towards the part)
  double half_field;      // half opening angle of the scan, radians
};

// Scanners drop returns beyond ~84 degrees of incidence.
constexpr double kMinIncidenceCos = 0.1;

Samples sample_scan(const SurfaceMesh& mesh, const SampleParams& p, const Vec& centre,
                    double diagonal, Rng& rng) {
  const RayCaster caster(mesh);
  const int views = std::uniform_int_distribution<int>(1, p.viewpoints)(rng);
  std::vector<Viewpoint> viewpoints;
  std::normal_distribution<double> normal_draw;
  nlohmann::json view_log = nlohmann::json::array();
  for (int v = 0; v < views; ++v) {
    const Vec direction = Vec(normal_draw(rng), normal_draw(rng), normal_draw(rng)).normalized();
    const double distance = uniform(rng, 1.0, 3.0) * diagonal;
    Viewpoint view;
    view.position = centre + distance * direction;
    const Vec forward = -direction;
    const Vec helper = std::abs(forward.z()) < 0.9 ? Vec(0, 0, 1) : Vec(1, 0, 0);
    const Vec right = forward.cross(helper).normalized();
    view.frame.col(0) = right;
    view.frame.col(1) = right.cross(forward);
    view.frame.col(2) = forward;
    // A third of the scans see only part of the part (scan borders).
    const double part_half = std::atan(0.5 * diagonal / distance);
    view.half_field = part_half * (uniform(rng, 0.0, 1.0) < 0.3 ? uniform(rng, 0.4, 0.9) : 1.1);
    viewpoints.push_back(view);
    view_log.push_back({{"distance_diagonals", distance / diagonal},
                        {"half_field_degrees", view.half_field * 180.0 / kPi}});
  }

  // Rows (scan lines) are 1-3 times further apart than the returns along a line. The angular
  // step follows from a coarse first pass that measures how much of the field the part fills.
  const double row_ratio = uniform(rng, 1.0, 3.0);
  double covered = 0.0;
  for (const Viewpoint& view : viewpoints) {
    constexpr int kProbe = 48;
    int hits = 0;
    for (int i = 0; i < kProbe; ++i)
      for (int j = 0; j < kProbe; ++j) {
        const double ax = view.half_field * (2.0 * (i + 0.5) / kProbe - 1.0);
        const double ay = view.half_field * (2.0 * (j + 0.5) / kProbe - 1.0);
        const Vec d = (view.frame * Vec(std::tan(ax), std::tan(ay), 1.0)).normalized();
        hits += std::isfinite(caster.cast(view.position, d));
      }
    covered += 4.0 * view.half_field * view.half_field * hits / (kProbe * kProbe);
  }
  const double step = std::sqrt(std::max(covered, 1e-12) / (p.points * row_ratio));

  Samples s;
  for (std::size_t v = 0; v < viewpoints.size(); ++v) {
    const Viewpoint& view = viewpoints[v];
    const double row_step = row_ratio * step;
    const int rows = static_cast<int>(std::ceil(2.0 * view.half_field / row_step));
    const int columns = static_cast<int>(std::ceil(2.0 * view.half_field / step));
    for (int r = 0; r < rows; ++r) {
      // Each line starts at a random offset, as a spinning mirror's lines do.
      const double ay = -view.half_field + (r + 0.5) * row_step;
      const double offset = uniform(rng, 0.0, step);
      for (int c = 0; c < columns; ++c) {
        const double ax = -view.half_field + offset + c * step;
        const Vec d = (view.frame * Vec(std::tan(ax), std::tan(ay), 1.0)).normalized();
        Vec normal;
        const double range = caster.cast(view.position, d, &normal);
        if (!std::isfinite(range)) continue;
        const double incidence = std::abs(normal.dot(d));
        if (incidence < kMinIncidenceCos) continue;
        if (normal.dot(d) > 0) normal = -normal;
        s.positions.push_back(view.position + range * d);
        s.normals.push_back(normal);
        s.spacing.push_back(range * std::sqrt(step * row_step / incidence));
      }
    }
  }
  if (s.positions.empty()) throw Error("scan", "", "no ray hit the part");

  // Surface that no viewpoint sees (outside every field, occluded, or at grazing incidence):
  // probe points on the surface, a third of the finest spacing apart, each tested against every
  // viewpoint; a hit next to an unseen probe lies at a scan or occlusion border.
  std::vector<double> sorted = s.spacing;
  std::sort(sorted.begin(), sorted.end());
  const double probe_spacing = sorted[sorted.size() / 10] / 3.0;
  const SurfaceSampler sampler(mesh);
  const auto probes =
      static_cast<std::size_t>(std::min(1.5e6, sampler.area() / (probe_spacing * probe_spacing)));
  std::vector<Vec> unseen;
  for (std::size_t i = 0; i < probes; ++i) {
    Vec q, n;
    sampler.draw(rng, q, n);
    bool seen = false;
    for (const Viewpoint& view : viewpoints) {
      const Vec to_probe = q - view.position;
      const double distance = to_probe.norm();
      const Vec d = to_probe / distance;
      const Vec local = view.frame.transpose() * d;
      if (local.z() <= 0 || std::abs(std::atan2(local.x(), local.z())) > view.half_field ||
          std::abs(std::atan2(local.y(), local.z())) > view.half_field)
        continue;
      if (std::abs(n.dot(d)) < kMinIncidenceCos) continue;
      if (caster.cast(view.position, d) >= distance - 1e-4 * diagonal) {
        seen = true;
        break;
      }
    }
    if (!seen) unseen.push_back(q);
  }
  // Unseen probes as zero-length boundary segments: the same band lookup as the B-rep's borders.
  std::vector<edges::FeatureSegment> borders;
  borders.reserve(unseen.size());
  for (const Vec& q : unseen) borders.push_back({q, q, edges::kLabelBoundary});
  const double max_band = p.boundary_band * sorted.back();
  const edges::FeatureIndex border_index(borders, max_band);
  s.not_seen.resize(s.positions.size());
  for (std::size_t i = 0; i < s.positions.size(); ++i)
    s.not_seen[i] = border_index.label(s.positions[i], 0.0, p.boundary_band * s.spacing[i]) ==
                    edges::kLabelBoundary;
  s.description = {{"viewpoints", view_log},
                   {"angular_step_degrees", step * 180.0 / kPi},
                   {"row_step_ratio", row_ratio},
                   {"probes", probes},
                   {"unseen_probes", unseen.size()}};
  return s;
}

// Noise, outliers and labels from the feature curves (the rule of sample.h), shared by B-rep
// parts and meshes. `edge_source` names the curves' origin in the description.
LabelledCloud label_samples(const Samples& samples, const EdgeClasses& classes,
                            const SampleParams& params, const Vec& centre, double diagonal,
                            const std::string& edge_source, Rng& rng) {
  const std::size_t n = samples.positions.size();
  if (n == 0) throw Error("shape", "sampling", "gave no points");
  std::vector<double> sorted = samples.spacing;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double median_spacing = sorted[n / 2];
  const double largest_spacing = *std::max_element(samples.spacing.begin(), samples.spacing.end());
  const edges::FeatureIndex features(classes.segments,
                                     std::max(params.band, params.boundary_band) * largest_spacing);

  std::normal_distribution<double> normal_draw;
  PointCloud cloud;
  cloud.reserve(n);
  std::vector<std::uint8_t> labels(n);
  std::size_t counts[3] = {0, 0, 0}, outliers = 0;
  const double scale = params.normalise ? 1.0 / diagonal : 1.0;
  const Vec origin = params.normalise ? centre : Vec::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    Vec p = samples.positions[i];
    const double local = samples.spacing[i];
    auto label_at = [&](const Vec& q) {
      return features.label(q, params.band * local, params.boundary_band * local);
    };
    std::uint8_t label = label_at(p);
    if (!samples.not_seen.empty() && samples.not_seen[i]) label = edges::kLabelBoundary;
    if (params.noise > 0.0)
      p += params.noise * median_spacing * normal_draw(rng) * samples.normals[i];
    if (params.outlier_share > 0.0 && uniform(rng, 0.0, 1.0) < params.outlier_share) {
      const Vec direction = Vec(normal_draw(rng), normal_draw(rng), normal_draw(rng)).normalized();
      p += uniform(rng, 2.0, 15.0) * median_spacing * direction;
      label = label_at(p);
      ++outliers;
    }
    p = (p - origin) * scale;
    cloud.push_back(float(p.x()), float(p.y()), float(p.z()));
    labels[i] = label;
    ++counts[label];
  }
  cloud.set("label", std::move(labels));

  LabelledCloud result;
  result.cloud = std::move(cloud);
  result.description = {
      {"sampling", sampling_names()[static_cast<std::size_t>(params.sampling)]},
      {"sampling_details", samples.description},
      {"points", n},
      {"median_spacing", median_spacing * scale},
      {"diagonal", diagonal * scale},
      {"normalised", params.normalise},
      {"noise_spacings", params.noise},
      {"outliers", outliers},
      {"band_spacings", params.band},
      {"boundary_band_spacings", params.boundary_band},
      {"sharp_angle_degrees", params.sharp_angle_deg},
      {edge_source,
       {{"sharp", classes.sharp},
        {"smooth", classes.smooth},
        {"boundary", classes.boundary},
        {"sharp_length", classes.sharp_length * scale},
        {"boundary_length", classes.boundary_length * scale}}},
      {"labels", {{"non-edge", counts[0]}, {"sharp-edge", counts[1]}, {"boundary", counts[2]}}}};
  return result;
}

}  // namespace

const std::vector<std::string>& sampling_names() {
  static const std::vector<std::string> names{"vertices", "uniform", "scan"};
  return names;
}

Sampling parse_sampling(const std::string& name) {
  const auto& names = sampling_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw Error("--sampling", name,
                fmt::format("unknown sampling; known: {}", fmt::join(names, ", ")));
  return static_cast<Sampling>(it - names.begin());
}

void check_sample_params(const SampleParams& p) {
  const std::string where = "sample parameters";
  if (p.points < 100 || p.points > 50000000)
    throw Error(where, "points", "must be in [100, 50,000,000]");
  if (!(p.band > 0.0 && p.band <= 5.0)) throw Error(where, "band", "must be in (0, 5] spacings");
  if (!(p.boundary_band > 0.0 && p.boundary_band <= 5.0))
    throw Error(where, "boundary_band", "must be in (0, 5] spacings");
  if (!(p.sharp_angle_deg >= 1.0 && p.sharp_angle_deg <= 150.0))
    throw Error(where, "sharp_angle", "must be in [1, 150] degrees");
  if (!(p.linear_deflection >= 1e-5 && p.linear_deflection <= 0.1))
    throw Error(where, "linear_deflection", "must be in [1e-5, 0.1] diagonals");
  if (!(p.angular_deflection_deg >= 1.0 && p.angular_deflection_deg <= 90.0))
    throw Error(where, "angular_deflection", "must be in [1, 90] degrees");
  if (!(p.plane_edge_fraction == 0.0 ||
        (p.plane_edge_fraction >= 1e-3 && p.plane_edge_fraction <= 1.0)))
    throw Error(where, "plane_edge_fraction", "must be 0 or in [0.001, 1] diagonals");
  if (p.viewpoints < 1 || p.viewpoints > 16) throw Error(where, "viewpoints", "must be in [1, 16]");
  if (!(p.noise >= 0.0 && p.noise <= 5.0))
    throw Error(where, "noise", "must be in [0, 5] spacings");
  if (!(p.outlier_share >= 0.0 && p.outlier_share <= 0.5))
    throw Error(where, "outliers", "must be in [0, 0.5]");
}

std::uint8_t classify_edge(const TopoDS_Edge& edge, const TopTools_ListOfShape& faces,
                           double sharp_angle_deg) {
  if (BRep_Tool::Degenerated(edge) || faces.IsEmpty()) return kNotAFeature;
  if (faces.Extent() == 1)  // a seam (both sides on one periodic face) is no border
    return BRep_Tool::IsClosed(edge, TopoDS::Face(faces.First())) ? kNotAFeature
                                                                  : edges::kLabelBoundary;
  if (faces.Extent() > 2) return edges::kLabelSharp;
  // Dihedral angle between the outward normals of the two faces, at 9 points of the edge.
  const TopoDS_Face f0 = TopoDS::Face(faces.First()), f1 = TopoDS::Face(faces.Last());
  double first = 0.0, last = 0.0, first0, last0, first1, last1;
  BRep_Tool::Range(edge, first, last);
  const Handle(Geom2d_Curve) c0 = BRep_Tool::CurveOnSurface(edge, f0, first0, last0);
  const Handle(Geom2d_Curve) c1 = BRep_Tool::CurveOnSurface(edge, f1, first1, last1);
  if (c0.IsNull() || c1.IsNull()) return edges::kLabelSharp;  // nothing to compare: keep it
  const BRepAdaptor_Surface s0(f0), s1(f1);
  double largest = 0.0;
  for (int k = 0; k < 9; ++k) {
    const double t = first + (last - first) * (k + 0.5) / 9.0;
    const gp_Pnt2d uv0 = c0->Value(t), uv1 = c1->Value(t);
    BRepLProp_SLProps p0(s0, uv0.X(), uv0.Y(), 1, 1e-9), p1(s1, uv1.X(), uv1.Y(), 1, 1e-9);
    if (!p0.IsNormalDefined() || !p1.IsNormalDefined()) continue;
    gp_Dir n0 = p0.Normal(), n1 = p1.Normal();
    if (f0.Orientation() == TopAbs_REVERSED) n0.Reverse();
    if (f1.Orientation() == TopAbs_REVERSED) n1.Reverse();
    largest = std::max(largest, n0.Angle(n1));
  }
  return largest >= sharp_angle_deg * kPi / 180.0 ? edges::kLabelSharp : 0;
}

void EdgeClasses::count(std::uint8_t label, double length) {
  if (label == edges::kLabelSharp) {
    ++sharp;
    sharp_length += length;
  } else if (label == edges::kLabelBoundary) {
    ++boundary;
    boundary_length += length;
  } else {
    ++smooth;
  }
}

EdgeClasses classify_edges(const TopoDS_Shape& shape, double sharp_angle_deg,
                           double polyline_tolerance) {
  EdgeClasses classes;
  TopTools_IndexedDataMapOfShapeListOfShape faces_of_edge;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, faces_of_edge);
  for (int i = 1; i <= faces_of_edge.Extent(); ++i) {
    const TopoDS_Edge edge = TopoDS::Edge(faces_of_edge.FindKey(i));
    const std::uint8_t label = classify_edge(edge, faces_of_edge(i), sharp_angle_deg);
    if (label == kNotAFeature) continue;
    // The edge as a polyline within the tolerance (straight edges give their two ends).
    BRepAdaptor_Curve curve(edge);
    GCPnts_TangentialDeflection points(curve, 0.05, polyline_tolerance, 2);
    double length = 0.0;
    for (int k = 1; k < points.NbPoints(); ++k) {
      const Vec a = to_vec(points.Value(k)), b = to_vec(points.Value(k + 1));
      length += (b - a).norm();
      if (label) classes.segments.push_back({a, b, label});
    }
    classes.count(label, length);
  }
  return classes;
}

LabelledCloud sample_shape(const TopoDS_Shape& shape, const SampleParams& params) {
  check_sample_params(params);
  if (shape.IsNull() || !TopExp_Explorer(shape, TopAbs_FACE).More())
    throw Error("shape", "", "has no faces to sample");
  const auto [low, high] = shape_bounds(shape);
  const Vec centre = 0.5 * (low + high);
  const double diagonal = (high - low).norm();
  Rng rng(params.seed);

  Samples samples;
  EdgeClasses classes;
  try {
    classes = classify_edges(shape, params.sharp_angle_deg, 1e-4 * diagonal);
    switch (params.sampling) {
      case Sampling::vertices: {
        // Each face is triangulated apart: its copies of the edges' nodes are welded.
        SurfaceMesh mesh = tessellate(shape, params.linear_deflection * diagonal,
                                      params.angular_deflection_deg * kPi / 180.0);
        geometry::weld_vertices(mesh, 1e-7 * diagonal);
        samples = sample_vertices(std::move(mesh), params, diagonal, rng);
        samples.description["linear_deflection"] = params.linear_deflection;
        samples.description["angular_deflection_degrees"] = params.angular_deflection_deg;
        break;
      }
      case Sampling::uniform:
        samples = sample_uniform(fine_mesh(shape, diagonal), params, rng);
        break;
      case Sampling::scan:
        samples = sample_scan(fine_mesh(shape, diagonal), params, centre, diagonal, rng);
        break;
    }
  } catch (const Standard_Failure& e) {
    throw Error("shape", "", std::string("kernel: ") + e.GetMessageString());
  }
  return label_samples(samples, classes, params, centre, diagonal, "brep_edges", rng);
}

LabelledCloud sample_mesh(SurfaceMesh mesh, const SampleParams& params, const std::string& name,
                          const EdgeClasses* sharp_curves) {
  check_sample_params(params);
  if (mesh.triangles.empty()) throw Error(name, "", "has no triangles to sample");
  Vec low = mesh.vertices.front(), high = low;
  for (const Vec& v : mesh.vertices) low = low.cwiseMin(v), high = high.cwiseMax(v);
  const Vec centre = 0.5 * (low + high);
  const double diagonal = (high - low).norm();
  if (!(diagonal > 0) || !std::isfinite(diagonal))
    throw Error(name, "vertices", "span no extent or are not finite");
  // Copies of a vertex (an OBJ's seams, an STL's unshared corners) would split every edge.
  geometry::weld_vertices(mesh, 1e-7 * diagonal);
  double area = 0.0;
  for (const auto& t : mesh.triangles) area += triangle_area(mesh, t);
  if (!(area > 0)) throw Error(name, "triangles", "are all degenerate (the surface has no area)");
  EdgeClasses classes = classify_mesh_edges(mesh, params.sharp_angle_deg);
  if (sharp_curves) {
    std::erase_if(classes.segments, [](const edges::FeatureSegment& segment) {
      return segment.label == edges::kLabelSharp;
    });
    classes.segments.insert(classes.segments.end(), sharp_curves->segments.begin(),
                            sharp_curves->segments.end());
    classes.sharp = sharp_curves->sharp;
    classes.smooth = sharp_curves->smooth;
    classes.sharp_length = 0.0;
    for (const edges::FeatureSegment& segment : sharp_curves->segments)
      classes.sharp_length += (segment.b - segment.a).norm();
  }
  Rng rng(params.seed);
  Samples samples;
  switch (params.sampling) {
    case Sampling::vertices:
      samples = sample_vertices(std::move(mesh), params, diagonal, rng);
      break;
    case Sampling::uniform:
      samples = sample_uniform(mesh, params, rng);
      break;
    case Sampling::scan:
      samples = sample_scan(mesh, params, centre, diagonal, rng);
      break;
  }
  LabelledCloud result =
      label_samples(samples, classes, params, centre, diagonal, "mesh_edges", rng);
  // With ABC's curves, "sharp" and "smooth" count curves, not mesh edges.
  result.description["sharp_from"] = sharp_curves ? "ABC features" : "dihedral angle";
  return result;
}

}  // namespace glint::cad
