#include "cad/part.h"

#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepFilletAPI_MakeChamfer.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepGProp.hxx>
#include <BRepOffsetAPI_MakeThickSolid.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRepPrimAPI_MakeRevol.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <mutex>
#include <random>

#include "cad/sample.h"
#include "core/error.h"

namespace glint::cad {
namespace {

using Rng = std::mt19937_64;
constexpr double kPi = 3.14159265358979323846;

double uniform(Rng& rng, double low, double high) {
  return std::uniform_real_distribution<double>(low, high)(rng);
}
int uniform_int(Rng& rng, int low, int high) {
  return std::uniform_int_distribution<int>(low, high)(rng);
}
bool chance(Rng& rng, double probability) { return uniform(rng, 0.0, 1.0) < probability; }

std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

// Cancels a kernel operation (through OCCT's progress interface) once its time is up.
class Deadline : public Message_ProgressIndicator {
 public:
  explicit Deadline(double seconds)
      : end_(std::chrono::steady_clock::now() +
             std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                 std::chrono::duration<double>(seconds))) {}
  Standard_Boolean UserBreak() override { return expired(); }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  bool expired() const { return std::chrono::steady_clock::now() > end_; }

 private:
  std::chrono::steady_clock::time_point end_;
};

// OpenCASCADE 7.6's modelling algorithms are not reentrant: the fillet builder keeps a file-scope
// static mode flag (TopOpeBRepBuild's STATIC_SOLIDINDEX; OCCT pull request #1374), so two
// threads modelling independent parts corrupt each other's solids or crash. Modelling holds this
// process-wide lock; tessellation and sampling of the finished parts run in parallel.
std::recursive_mutex& modelling_mutex() {
  static std::recursive_mutex mutex;
  return mutex;
}

struct Box {
  double x0, y0, z0, x1, y1, z1;
  double dx() const { return x1 - x0; }
  double dy() const { return y1 - y0; }
  double dz() const { return z1 - z0; }
  double smallest() const { return std::min({dx(), dy(), dz()}); }
};

Box bounding_box(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  Box b{};
  box.Get(b.x0, b.y0, b.z0, b.x1, b.y1, b.z1);
  return b;
}

// Whether make(range) runs to its end in a forked child process: the failure ("kernel crashed
// (signal N)", "timed out") if not, else empty. OpenCASCADE 7.6 crashes on some valid solids (a
// fillet: SIGSEGV in TopOpeBRepBuild's face builder); the child inherits the kernel's whole
// state, so it crashes exactly where this process would. Operations that survive then run here,
// so their results are the kernel's in this process, bit for bit (docs/decisions.md, "Fillets
// and chamfers tried in a child process first"). A child that outlives the time limit by
// kChildGrace_s (e.g. stuck on a lock another thread held at the fork) is killed.
template <class Make>
std::string kernel_crash(Make& make, double time_limit_s) {
  constexpr double kChildGrace_s = 30.0;
  int fds[2];
  if (::pipe(fds) != 0) throw Error("cad modelling", "pipe", std::strerror(errno));
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]), ::close(fds[1]);
    throw Error("cad modelling", "fork", std::strerror(errno));
  }
  if (pid == 0) {  // child: its end of the pipe closes when it exits, however it exits
    ::close(fds[0]);
    try {
      Handle(Deadline) deadline = new Deadline(time_limit_s);
      make(deadline->Start());
    } catch (...) {
      // Kernel errors are caught again when the operation runs in the parent.
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  const auto give_up = std::chrono::steady_clock::now() +
                       std::chrono::duration<double>(time_limit_s + kChildGrace_s);
  // The pipe reads as ready when the child has exited; poll returning 0 means time is up.
  int ready = 0;
  do {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        give_up - std::chrono::steady_clock::now());
    pollfd hang_up{fds[0], POLLIN, 0};
    ready = left.count() > 0 ? ::poll(&hang_up, 1, int(left.count())) : 0;
  } while (ready < 0 && errno == EINTR);
  const bool killed = ready == 0;
  if (killed) ::kill(pid, SIGKILL);
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (killed) return "timed out";
  if (WIFSIGNALED(status)) return fmt::format("kernel crashed (signal {})", WTERMSIG(status));
  // A sanitizer's crash report exits instead of dying of the signal.
  if (WEXITSTATUS(status) != 0)
    return fmt::format("kernel crashed (exit status {})", WEXITSTATUS(status));
  return {};
}

// Applies kernel operations one by one; a failed one leaves the shape as it was and is logged.
class Modeller {
 public:
  Modeller(TopoDS_Shape shape, nlohmann::json& recipe, double time_limit_s)
      : shape_(std::move(shape)), recipe_(recipe), time_limit_s_(time_limit_s) {}

  const TopoDS_Shape& shape() const { return shape_; }

  // make(range) builds the new shape from shape() or returns a null shape. A crash_prone
  // operation runs here only if it survived a child process (kernel_crash), which doubles its
  // time: fillets and chamfers, whose builder is where the kernel crashed on valid solids.
  template <class Make>
  bool apply(nlohmann::json operation, Make make, bool crash_prone = false) {
    std::string failure = crash_prone ? kernel_crash(make, time_limit_s_) : std::string();
    if (failure.empty()) {
      Handle(Deadline) deadline = new Deadline(time_limit_s_);
      try {
        TopoDS_Shape result = make(deadline->Start());
        if (deadline->expired()) {
          failure = "timed out";
        } else if (result.IsNull()) {
          failure = "not done";
        } else if (!BRepCheck_Analyzer(result).IsValid()) {
          failure = "invalid result";
        } else {
          shape_ = result;
          recipe_["operations"].push_back(std::move(operation));
          return true;
        }
      } catch (const Standard_Failure& e) {
        failure = std::string("kernel: ") + e.GetMessageString();
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    if (failure == "timed out") recipe_["timed_out"] = true;
    operation["failed"] = failure;
    recipe_["skipped"].push_back(std::move(operation));
    return false;
  }

 private:
  TopoDS_Shape shape_;
  nlohmann::json& recipe_;
  double time_limit_s_;
};

template <class Algorithm>
TopoDS_Shape result_of(Algorithm& algorithm, const Message_ProgressRange& range) {
  algorithm.Build(range);
  return algorithm.IsDone() ? algorithm.Shape() : TopoDS_Shape();
}

TopoDS_Shape boolean_cut(const TopoDS_Shape& shape, const TopoDS_Shape& tool,
                         const Message_ProgressRange& range) {
  BRepAlgoAPI_Cut cut;
  TopTools_ListOfShape arguments, tools;
  arguments.Append(shape);
  tools.Append(tool);
  cut.SetArguments(arguments);
  cut.SetTools(tools);
  cut.Build(range);
  return cut.IsDone() && !cut.HasErrors() ? cut.Shape() : TopoDS_Shape();
}

TopoDS_Shape boolean_fuse(const TopoDS_Shape& shape, const TopoDS_Shape& tool,
                          const Message_ProgressRange& range) {
  BRepAlgoAPI_Fuse fuse;
  TopTools_ListOfShape arguments, tools;
  arguments.Append(shape);
  tools.Append(tool);
  fuse.SetArguments(arguments);
  fuse.SetTools(tools);
  fuse.Build(range);
  return fuse.IsDone() && !fuse.HasErrors() ? fuse.Shape() : TopoDS_Shape();
}

TopoDS_Shape prism_of_polygon(const std::vector<gp_Pnt>& corners, const gp_Vec& direction) {
  BRepBuilderAPI_MakePolygon polygon;
  for (const gp_Pnt& p : corners) polygon.Add(p);
  polygon.Close();
  const TopoDS_Face face = BRepBuilderAPI_MakeFace(polygon.Wire(), true).Face();
  return BRepPrimAPI_MakePrism(face, direction).Shape();
}

// ---- base solids (millimetre-like units; the sampler normalises).

TopoDS_Shape make_base(PartRecipe recipe, Rng& rng, nlohmann::json& base) {
  switch (recipe) {
    case PartRecipe::block:
    case PartRecipe::plate: {
      const bool plate = recipe == PartRecipe::plate;
      const double length = plate ? uniform(rng, 60, 150) : uniform(rng, 40, 120);
      const double width = uniform(rng, 0.3, 1.0) * length;
      const double height = plate ? uniform(rng, 3, 12) : uniform(rng, 0.15, 0.8) * length;
      base = {{"size", {length, width, height}}};
      return BRepPrimAPI_MakeBox(length, width, height).Shape();
    }
    case PartRecipe::extrusion: {
      std::vector<gp_Pnt> corners;
      if (chance(rng, 0.5)) {
        // Star-shaped random polygon.
        const int n = uniform_int(rng, 4, 9);
        std::vector<double> angles;
        for (int i = 0; i < n; ++i) angles.push_back(uniform(rng, 0.0, 2.0 * kPi));
        std::sort(angles.begin(), angles.end());
        for (double a : angles) {
          const double r = uniform(rng, 20, 50);
          corners.emplace_back(r * std::cos(a), r * std::sin(a), 0.0);
        }
        base["profile"] = "polygon";
      } else {
        // Rectilinear L / U / T profile: a staircase outline of random steps.
        const double w = uniform(rng, 40, 100), t = uniform(rng, 6, 0.4 * w);
        const double h = uniform(rng, 30, 90);
        const int kind = uniform_int(rng, 0, 2);
        if (kind == 0)
          corners = {{0, 0, 0}, {w, 0, 0}, {w, t, 0}, {t, t, 0}, {t, h, 0}, {0, h, 0}};
        else if (kind == 1)
          corners = {{0, 0, 0},     {w, 0, 0}, {w, h, 0}, {w - t, h, 0},
                     {w - t, t, 0}, {t, t, 0}, {t, h, 0}, {0, h, 0}};
        else
          corners = {{0, 0, 0},
                     {w, 0, 0},
                     {w, t, 0},
                     {0.5 * (w + t), t, 0},
                     {0.5 * (w + t), h, 0},
                     {0.5 * (w - t), h, 0},
                     {0.5 * (w - t), t, 0},
                     {0, t, 0}};
        base["profile"] = std::array<const char*, 3>{"L", "U", "T"}[kind];
      }
      const double depth = uniform(rng, 10, 80);
      base["depth"] = depth;
      base["corners"] = corners.size();
      return prism_of_polygon(corners, gp_Vec(0, 0, depth));
    }
    case PartRecipe::turned: {
      // Profile in the xz half-plane (x = radius), revolved about z: steps and tapers.
      const int steps = uniform_int(rng, 2, 5);
      std::vector<gp_Pnt> corners{{0, 0, 0}};
      double z = 0.0;
      for (int i = 0; i < steps; ++i) {
        const double r = uniform(rng, 8, 40), length = uniform(rng, 5, 30);
        if (i > 0 && chance(rng, 0.3)) {  // taper into this step
          corners.emplace_back(r, 0, z + uniform(rng, 2, 10));
        } else {
          corners.emplace_back(r, 0, z);
        }
        z = std::max(z + length, corners.back().Z() + 2.0);
        corners.emplace_back(r, 0, z);
      }
      corners.emplace_back(0, 0, z);
      BRepBuilderAPI_MakePolygon polygon;
      for (const gp_Pnt& p : corners) polygon.Add(p);
      polygon.Close();
      const TopoDS_Face face = BRepBuilderAPI_MakeFace(polygon.Wire(), true).Face();
      base = {{"steps", steps}, {"length", z}};
      return BRepPrimAPI_MakeRevol(face, gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 2.0 * kPi)
          .Shape();
    }
    case PartRecipe::cylinder: {
      const double r = uniform(rng, 15, 50), h = uniform(rng, 10, 100);
      if (chance(rng, 0.3)) {
        const double r2 = r * uniform(rng, 0.3, 0.8);
        base = {{"cone_radii", {r, r2}}, {"height", h}};
        return BRepPrimAPI_MakeCone(r, r2, h).Shape();
      }
      base = {{"radius", r}, {"height", h}};
      return BRepPrimAPI_MakeCylinder(r, h).Shape();
    }
  }
  return {};
}

// ---- features: tools placed on the top (+z) of the bounding box, or across it.

void add_feature(Modeller& modeller, Rng& rng) {
  const Box b = bounding_box(modeller.shape());
  const double small = std::min(b.dx(), b.dy());
  const double x = b.x0 + uniform(rng, 0.15, 0.85) * b.dx();
  const double y = b.y0 + uniform(rng, 0.15, 0.85) * b.dy();
  const int kind = uniform_int(rng, 0, 5);
  const double through = b.dz() + 2.0;
  switch (kind) {
    case 0:    // through hole along z
    case 1: {  // blind hole
      const double r = uniform(rng, 0.03, 0.15) * small;
      const double depth = kind == 0 ? through : uniform(rng, 0.2, 0.7) * b.dz();
      const double z0 = kind == 0 ? b.z0 - 1.0 : b.z1 - depth;
      const TopoDS_Shape tool =
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, z0), gp_Dir(0, 0, 1)), r, depth + 1.0)
              .Shape();
      modeller.apply({{"op", kind == 0 ? "hole" : "blind_hole"}, {"radius", r}, {"depth", depth}},
                     [&](const Message_ProgressRange& range) {
                       return boolean_cut(modeller.shape(), tool, range);
                     });
      break;
    }
    case 2: {  // cross hole along x or y
      const bool along_x = chance(rng, 0.5);
      const double r = uniform(rng, 0.05, 0.3) * b.dz();
      const double z = b.z0 + uniform(rng, 0.3, 0.7) * b.dz();
      const gp_Pnt start = along_x ? gp_Pnt(b.x0 - 1.0, y, z) : gp_Pnt(x, b.y0 - 1.0, z);
      const double length = (along_x ? b.dx() : b.dy()) + 2.0;
      const TopoDS_Shape tool =
          BRepPrimAPI_MakeCylinder(gp_Ax2(start, along_x ? gp_Dir(1, 0, 0) : gp_Dir(0, 1, 0)), r,
                                   length)
              .Shape();
      modeller.apply({{"op", "cross_hole"}, {"radius", r}},
                     [&](const Message_ProgressRange& range) {
                       return boolean_cut(modeller.shape(), tool, range);
                     });
      break;
    }
    case 3:    // rectangular pocket
    case 4: {  // slot, straight or with rounded ends
      const bool slot = kind == 4;
      const double sx = slot ? uniform(rng, 0.3, 0.7) * b.dx() : uniform(rng, 0.1, 0.4) * b.dx();
      const double sy = slot ? uniform(rng, 0.04, 0.15) * b.dy() : uniform(rng, 0.1, 0.4) * b.dy();
      const bool through_slot = slot && chance(rng, 0.4);
      const double depth = through_slot ? through : uniform(rng, 0.15, 0.6) * b.dz();
      const double z0 = through_slot ? b.z0 - 1.0 : b.z1 - depth;
      const double cx = std::clamp(x, b.x0 + 0.5 * sx + 1.0, b.x1 - 0.5 * sx - 1.0);
      TopoDS_Shape tool =
          BRepPrimAPI_MakeBox(gp_Pnt(cx - 0.5 * sx, y - 0.5 * sy, z0), sx, sy, depth + 1.0).Shape();
      const bool rounded = slot && chance(rng, 0.5);
      if (rounded)
        for (double end : {cx - 0.5 * sx, cx + 0.5 * sx})
          tool = BRepAlgoAPI_Fuse(
                     tool, BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(end, y, z0), gp_Dir(0, 0, 1)),
                                                    0.5 * sy, depth + 1.0)
                               .Shape())
                     .Shape();
      modeller.apply({{"op", slot ? "slot" : "pocket"},
                      {"size", {sx, sy}},
                      {"depth", depth},
                      {"rounded_ends", rounded}},
                     [&](const Message_ProgressRange& range) {
                       return boolean_cut(modeller.shape(), tool, range);
                     });
      break;
    }
    case 5: {  // boss on top (sunk by 1 so that the fuse overlaps)
      const double r = uniform(rng, 0.04, 0.15) * small, h = uniform(rng, 0.1, 0.5) * b.dz() + 2.0;
      const TopoDS_Shape tool =
          BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, b.z1 - 1.0), gp_Dir(0, 0, 1)), r, h + 1.0)
              .Shape();
      modeller.apply({{"op", "boss"}, {"radius", r}, {"height", h}},
                     [&](const Message_ProgressRange& range) {
                       return boolean_fuse(modeller.shape(), tool, range);
                     });
      break;
    }
  }
}

// A random sharp edge (fillets and chamfers only apply where two faces meet at an angle).
TopoDS_Edge random_sharp_edge(const TopoDS_Shape& shape, Rng& rng) {
  TopTools_IndexedDataMapOfShapeListOfShape faces_of_edge;
  TopExp::MapShapesAndUniqueAncestors(shape, TopAbs_EDGE, TopAbs_FACE, faces_of_edge);
  std::vector<int> sharp;
  for (int i = 1; i <= faces_of_edge.Extent(); ++i)
    if (classify_edge(TopoDS::Edge(faces_of_edge.FindKey(i)), faces_of_edge(i), 25.0) ==
        edges::kLabelSharp)
      sharp.push_back(i);
  if (sharp.empty()) return {};
  return TopoDS::Edge(
      faces_of_edge.FindKey(sharp[uniform_int(rng, 0, static_cast<int>(sharp.size()) - 1)]));
}

void round_edges(Modeller& modeller, Rng& rng, bool chamfer) {
  const int count = chamfer ? uniform_int(rng, 1, 4) : uniform_int(rng, 1, 6);
  for (int i = 0; i < count; ++i) {
    const double size = uniform(rng, 0.02, 0.12) * bounding_box(modeller.shape()).smallest();
    const TopoDS_Edge edge = random_sharp_edge(modeller.shape(), rng);
    if (edge.IsNull()) return;
    modeller.apply(
        {{"op", chamfer ? "chamfer" : "fillet"}, {"size", size}},
        [&](const Message_ProgressRange& range) {
          if (chamfer) {
            BRepFilletAPI_MakeChamfer maker(modeller.shape());
            maker.Add(size, edge);
            return result_of(maker, range);
          }
          BRepFilletAPI_MakeFillet maker(modeller.shape());
          maker.Add(size, edge);
          return result_of(maker, range);
        },
        /*crash_prone=*/true);
  }
}

// The planar face facing +z with the highest position (largest if several).
TopoDS_Face top_face(const TopoDS_Shape& shape) {
  TopoDS_Face best;
  double best_z = -1e300, best_area = 0.0;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) {
    const TopoDS_Face face = TopoDS::Face(it.Current());
    BRepAdaptor_Surface surface(face);
    if (surface.GetType() != GeomAbs_Plane) continue;
    gp_Dir normal = surface.Plane().Axis().Direction();
    if (face.Orientation() == TopAbs_REVERSED) normal.Reverse();
    if (normal.Z() < 0.99) continue;
    GProp_GProps properties;
    BRepGProp::SurfaceProperties(face, properties);
    const double z = surface.Plane().Location().Z();
    if (z > best_z + 1e-6 || (std::abs(z - best_z) <= 1e-6 && properties.Mass() > best_area)) {
      best = face;
      best_z = z;
      best_area = properties.Mass();
    }
  }
  return best;
}

void hollow(Modeller& modeller, Rng& rng) {
  const TopoDS_Face top = top_face(modeller.shape());
  if (top.IsNull()) return;
  const double thickness = uniform(rng, 0.05, 0.15) * bounding_box(modeller.shape()).smallest();
  modeller.apply(
      {{"op", "shell"}, {"thickness", thickness}}, [&](const Message_ProgressRange& range) {
        TopTools_ListOfShape removed;
        removed.Append(top);
        BRepOffsetAPI_MakeThickSolid maker;
        maker.MakeThickSolidByJoin(modeller.shape(), removed, -thickness, 1e-3, BRepOffset_Skin,
                                   false, false, GeomAbs_Arc, false, range);
        return maker.IsDone() ? maker.Shape() : TopoDS_Shape();
      });
}

TopoDS_Shape without_faces(const TopoDS_Shape& shape, Rng& rng, nlohmann::json& opening) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  if (faces.Extent() < 3) return shape;
  const int removed = std::min(uniform_int(rng, 1, 2), faces.Extent() - 2);
  std::vector<int> order(faces.Extent());
  for (int i = 0; i < faces.Extent(); ++i) order[i] = i + 1;
  std::shuffle(order.begin(), order.end(), rng);
  TopoDS_Compound compound;
  BRep_Builder builder;
  builder.MakeCompound(compound);
  for (std::size_t i = removed; i < order.size(); ++i) builder.Add(compound, faces(order[i]));
  opening = {{"kind", "faces_removed"},
             {"faces_removed", std::vector<int>(order.begin(), order.begin() + removed)}};
  return compound;
}

}  // namespace

const std::vector<std::string>& part_recipe_names() {
  static const std::vector<std::string> names{"block", "plate", "extrusion", "turned", "cylinder"};
  return names;
}

PartRecipe parse_part_recipe(const std::string& name) {
  const auto& names = part_recipe_names();
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw Error("--recipes", name,
                fmt::format("unknown recipe; known: {}", fmt::join(names, ", ")));
  return static_cast<PartRecipe>(it - names.begin());
}

void check_part_params(const PartParams& p) {
  const std::string where = "part parameters";
  if (p.max_features < 0 || p.max_features > 50)
    throw Error(where, "max_features", "must be in [0, 50]");
  for (double probability : {p.fillet_probability, p.chamfer_probability, p.shell_probability,
                             p.plane_cut_probability, p.faces_removed_probability})
    if (!(probability >= 0.0 && probability <= 1.0))
      throw Error(where, "probability", "probabilities must be in [0, 1]");
  if (p.plane_cut_probability + p.faces_removed_probability > 1.0 + 1e-12)
    throw Error(where, "opening", "plane-cut and faces-removed shares add up to more than 1");
  if (!(p.operation_time_limit_s > 0.0)) throw Error(where, "time_limit", "must be positive");
}

std::array<Eigen::Vector3d, 2> shape_bounds(const TopoDS_Shape& shape) {
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  // An unbounded face (e.g. a plane without edges) has an open box, which OCCT reports as
  // ±1e100: deflections and spacings derived from it would mesh nothing.
  if (box.IsVoid() || box.IsOpen())
    throw Error("shape", "bounding box", "is empty or unbounded (a face without a boundary)");
  double x0, y0, z0, x1, y1, z1;
  box.Get(x0, y0, z0, x1, y1, z1);
  return {Eigen::Vector3d(x0, y0, z0), Eigen::Vector3d(x1, y1, z1)};
}

TopoDS_Shape cut_open(const TopoDS_Shape& shape, const double point[3], const double normal[3]) {
  const std::lock_guard lock(modelling_mutex());
  try {
    const gp_Dir n(normal[0], normal[1], normal[2]);
    const Box b = bounding_box(shape);
    const double size = 4.0 * std::sqrt(b.dx() * b.dx() + b.dy() * b.dy() + b.dz() * b.dz());
    // A box covering everything on the negative side of the plane.
    const gp_Ax2 frame(gp_Pnt(point[0], point[1], point[2]), n.Reversed());
    const gp_Pnt corner = gp_Pnt(point[0], point[1], point[2])
                              .Translated(-0.5 * size * gp_Vec(frame.XDirection()))
                              .Translated(-0.5 * size * gp_Vec(frame.YDirection()));
    const TopoDS_Shape negative_side =
        BRepPrimAPI_MakeBox(gp_Ax2(corner, frame.Direction(), frame.XDirection()), size, size, size)
            .Shape();
    // Cutting the shells rather than the solid leaves the surface open (no cap).
    TopoDS_Compound surfaces;
    BRep_Builder builder;
    builder.MakeCompound(surfaces);
    int count = 0;
    for (TopExp_Explorer it(shape, TopAbs_SHELL); it.More(); it.Next(), ++count)
      builder.Add(surfaces, it.Current());
    for (TopExp_Explorer it(shape, TopAbs_FACE, TopAbs_SHELL); it.More(); it.Next(), ++count)
      builder.Add(surfaces, it.Current());
    if (count == 0) throw Error("cut_open", "", "the shape has no faces");
    const TopoDS_Shape result = boolean_cut(surfaces, negative_side, Message_ProgressRange());
    if (result.IsNull()) throw Error("cut_open", "", "the kernel's boolean cut failed");
    if (!TopExp_Explorer(result, TopAbs_FACE).More())
      throw Error("cut_open", "", "nothing of the part lies on the kept side of the plane");
    return result;
  } catch (const Standard_Failure& e) {
    throw Error("cut_open", "", std::string("kernel: ") + e.GetMessageString());
  }
}

Part random_part(const PartParams& params, std::uint64_t index) {
  check_part_params(params);
  const std::lock_guard lock(modelling_mutex());
  Rng rng(splitmix64(params.seed ^ splitmix64(index)));
  const auto& names = part_recipe_names();
  const PartRecipe recipe =
      params.recipes.empty()
          ? static_cast<PartRecipe>(uniform_int(rng, 0, static_cast<int>(names.size()) - 1))
          : params.recipes[uniform_int(rng, 0, static_cast<int>(params.recipes.size()) - 1)];
  Part part;
  nlohmann::json& r = part.recipe;
  r = {{"seed", params.seed},
       {"index", index},
       {"recipe", names[static_cast<std::size_t>(recipe)]},
       {"operations", nlohmann::json::array()},
       {"skipped", nlohmann::json::array()}};
  nlohmann::json base;
  TopoDS_Shape shape;
  try {
    shape = make_base(recipe, rng, base);
  } catch (const Standard_Failure& e) {
    base["failed"] = std::string("kernel: ") + e.GetMessageString();
  }
  if (shape.IsNull()) {  // a profile the kernel refused: fall back to a plain block
    shape = BRepPrimAPI_MakeBox(60.0, 40.0, 20.0).Shape();
    base["fallback"] = "block 60 x 40 x 20";
  }
  r["base"] = base;

  Modeller modeller(shape, r, params.operation_time_limit_s);
  try {
    const int features = uniform_int(rng, 0, params.max_features);
    for (int i = 0; i < features; ++i) add_feature(modeller, rng);
    if (chance(rng, params.fillet_probability)) round_edges(modeller, rng, false);
    if (chance(rng, params.chamfer_probability)) round_edges(modeller, rng, true);
    if (chance(rng, params.shell_probability)) hollow(modeller, rng);
  } catch (const Standard_Failure& e) {
    // A tool the kernel could not even build: keep the part as modelled so far.
    r["stopped"] = std::string("kernel: ") + e.GetMessageString();
  }
  part.shape = modeller.shape();

  // The opening draws from its own stream: the part is the same whether or not it is opened.
  Rng open_rng(splitmix64(params.seed ^ splitmix64(index ^ 0x6f70656eULL)));
  const double draw = uniform(open_rng, 0.0, 1.0);
  nlohmann::json opening = {{"kind", "closed"}};
  if (draw < params.plane_cut_probability) {
    const Box b = bounding_box(part.shape);
    const double point[3] = {b.x0 + uniform(open_rng, 0.25, 0.75) * b.dx(),
                             b.y0 + uniform(open_rng, 0.25, 0.75) * b.dy(),
                             b.z0 + uniform(open_rng, 0.25, 0.75) * b.dz()};
    std::normal_distribution<double> normal_draw;
    double normal[3] = {normal_draw(open_rng), normal_draw(open_rng), normal_draw(open_rng)};
    if (std::abs(normal[0]) + std::abs(normal[1]) + std::abs(normal[2]) < 1e-9) normal[2] = 1.0;
    try {
      part.shape = cut_open(part.shape, point, normal);
      opening = {{"kind", "plane_cut"},
                 {"point", {point[0], point[1], point[2]}},
                 {"normal", {normal[0], normal[1], normal[2]}}};
    } catch (const Error& e) {
      opening = {{"kind", "closed"}, {"plane_cut_failed", e.reason()}};
    }
  } else if (draw < params.plane_cut_probability + params.faces_removed_probability) {
    part.shape = without_faces(part.shape, open_rng, opening);
  }
  r["opening"] = opening;
  return part;
}

}  // namespace glint::cad
