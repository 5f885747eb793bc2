// A mesh's own edges as ground truth: a cube's edges are sharp and its face diagonals smooth
// (whatever the winding), a finely tessellated cylinder's rims are sharp and its side smooth,
// and a plane cut leaves a boundary on the cut only, clipped or with the crossed triangles
// dropped.
#include "cad/surface_mesh.h"

#include <gtest/gtest.h>

#include <cmath>

#include "cad/sample.h"
#include "core/error.h"

namespace glint::cad {
namespace {

using Vec = Eigen::Vector3d;

SurfaceMesh unit_cube() {
  SurfaceMesh mesh;
  for (int i = 0; i < 8; ++i) mesh.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  // Two counter-clockwise triangles per face, seen from outside.
  mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                    {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return mesh;
}

// Radius 1, height 2 (z in [0, 2]), `segments` around, `rings` + 1 rows of side vertices, both
// caps as fans around a centre vertex.
constexpr double kHeight = 2.0;
SurfaceMesh cylinder(int segments, int rings) {
  SurfaceMesh mesh;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double angle = 2.0 * M_PI * s / segments;
      mesh.vertices.emplace_back(std::cos(angle), std::sin(angle), kHeight * r / rings);
    }
  auto at = [&](int r, int s) { return r * segments + (s % segments); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.push_back({at(r, s), at(r, s + 1), at(r + 1, s + 1)});
      mesh.triangles.push_back({at(r, s), at(r + 1, s + 1), at(r + 1, s)});
    }
  const int bottom = int(mesh.vertices.size()), top = bottom + 1;
  mesh.vertices.emplace_back(0, 0, 0);
  mesh.vertices.emplace_back(0, 0, kHeight);
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.push_back({bottom, at(0, s + 1), at(0, s)});
    mesh.triangles.push_back({top, at(rings, s), at(rings, s + 1)});
  }
  return mesh;
}

double polygon_perimeter(int segments) { return 2.0 * segments * std::sin(M_PI / segments); }

TEST(SurfaceMesh, ACubesEdgesAreSharpItsFaceDiagonalsSmooth) {
  SurfaceMesh cube = unit_cube();
  for (int flipped = 0; flipped < 2; ++flipped) {
    const EdgeClasses classes = classify_mesh_edges(cube, 25.0);
    EXPECT_EQ(classes.sharp, 12) << "flipped " << flipped;
    EXPECT_EQ(classes.smooth, 6);
    EXPECT_EQ(classes.boundary, 0);
    EXPECT_NEAR(classes.sharp_length, 12.0, 1e-12);
    // A triangle wound the other way round is compared as if it were consistent.
    std::swap(cube.triangles[3][1], cube.triangles[3][2]);
  }
}

TEST(SurfaceMesh, ATessellatedCylindersRimsAreSharpItsSideSmooth) {
  const EdgeClasses classes = classify_mesh_edges(cylinder(64, 4), 25.0);
  EXPECT_EQ(classes.sharp, 2 * 64);
  EXPECT_EQ(classes.boundary, 0);
  EXPECT_NEAR(classes.sharp_length, 2.0 * polygon_perimeter(64), 1e-9);
  // Neighbouring side triangles turn by 360 / 64 degrees: sharp only from a lower angle.
  EXPECT_EQ(classify_mesh_edges(cylinder(64, 4), 5.0).sharp, 2 * 64 + 4 * 64);
}

TEST(SurfaceMesh, ACutCylinderHasItsBoundaryOnTheCutOnly) {
  const double cut_height = 0.7;  // between the side's rings at 0.5 and 1.0
  const SurfaceMesh cut = cut_mesh(cylinder(64, 4), Vec(0, 0, cut_height), Vec(0, 0, 3));
  const EdgeClasses classes = classify_mesh_edges(cut, 25.0);
  EXPECT_EQ(classes.sharp, 64);  // the top rim
  EXPECT_NEAR(classes.boundary_length, polygon_perimeter(64), 1e-9);
  for (const auto& segment : classes.segments) {
    if (segment.label != edges::kLabelBoundary) continue;
    EXPECT_NEAR(segment.a.z(), cut_height, 1e-12);
    EXPECT_NEAR(segment.b.z(), cut_height, 1e-12);
  }
  for (const Vec& v : cut.vertices) EXPECT_GE(v.z(), cut_height - 1e-12);
}

TEST(SurfaceMesh, ADropCutEndsAtTheLastWholeTriangles) {
  // The side's rings lie at z = 0, 0.5, ..., 2: dropping every triangle with a corner below 0.7
  // leaves the border on the ring at 1.
  const SurfaceMesh cut = cut_mesh(cylinder(64, 4), Vec(0, 0, 0.7), Vec(0, 0, 1), CutMode::drop);
  const EdgeClasses classes = classify_mesh_edges(cut, 25.0);
  EXPECT_EQ(classes.boundary, 64);
  EXPECT_EQ(classes.sharp, 64);
  for (const auto& segment : classes.segments) {
    if (segment.label == edges::kLabelBoundary) {
      EXPECT_NEAR(segment.a.z(), 1.0, 1e-12);
    }
  }
  EXPECT_EQ(cut.vertices.size(), 3u * 64u + 1u);  // three rings and the top centre
}

TEST(SurfaceMesh, FeatureSegmentsAreCutAsTheMeshIs) {
  std::vector<edges::FeatureSegment> segments{{Vec(0, 0, -1), Vec(0, 0, 1), edges::kLabelSharp},
                                              {Vec(1, 0, 0.5), Vec(1, 0, 2), edges::kLabelSharp},
                                              {Vec(2, 0, -2), Vec(2, 0, -1), edges::kLabelSharp}};
  cut_segments(segments, Vec(0, 0, 0.25), Vec(0, 0, 2));
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_NEAR(segments[0].a.z(), 0.25, 1e-12);  // clipped where it crosses
  EXPECT_NEAR(segments[0].b.z(), 1.0, 1e-12);
  EXPECT_NEAR(segments[1].a.z(), 0.5, 1e-12);  // wholly kept
}

TEST(SurfaceMesh, ACutThatKeepsNothingFails) {
  EXPECT_THROW(cut_mesh(unit_cube(), Vec(0, 0, 2), Vec(0, 0, 1)), Error);
  EXPECT_THROW(cut_mesh(unit_cube(), Vec(0, 0, 0.5), Vec::Zero()), Error);
}

TEST(SurfaceMesh, VerticesOfACutCylinderAreLabelledFromItsEdges) {
  SampleParams params;
  params.sampling = Sampling::vertices;
  const LabelledCloud labelled =
      sample_mesh(cut_mesh(cylinder(64, 4), Vec(0, 0, 0.7), Vec(0, 0, 1)), params, "cylinder");
  const PointCloud& cloud = labelled.cloud;
  const auto& labels = *cloud.get<std::uint8_t>("label");
  int wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = cloud.point(i);
    const double z = p.z();
    const bool on_rim = std::abs(z - kHeight) < 1e-6 && p.head<2>().norm() > 0.5f;
    const std::uint8_t expected = std::abs(z - 0.7) < 1e-6 ? edges::kLabelBoundary
                                  : on_rim                 ? edges::kLabelSharp
                                                           : 0;
    wrong += labels[i] != expected;
  }
  EXPECT_EQ(wrong, 0);
  // The cut crosses each side quad's vertical edge and its diagonal: two border edges per quad.
  EXPECT_EQ(labelled.description["mesh_edges"]["boundary"].get<int>(), 128);
  EXPECT_EQ(labelled.description["labels"]["boundary"].get<int>(), 128);
  EXPECT_EQ(labelled.description["labels"]["sharp-edge"].get<int>(), 64);
}

TEST(SurfaceMesh, CopiesOfAVertexAreWeldedBeforeTheEdgesAreClassified) {
  // Each triangle with corners of its own, as an STL holds them: unwelded, every edge would be
  // a boundary.
  const SurfaceMesh cube = unit_cube();
  SurfaceMesh soup;
  for (const auto& t : cube.triangles) {
    const int first = int(soup.vertices.size());
    for (int corner : t) soup.vertices.push_back(cube.vertices[corner]);
    soup.triangles.push_back({first, first + 1, first + 2});
  }
  SampleParams params;
  params.sampling = Sampling::vertices;
  const LabelledCloud labelled = sample_mesh(soup, params, "soup");
  EXPECT_EQ(labelled.cloud.size(), 8u);
  EXPECT_EQ(labelled.description["mesh_edges"]["sharp"].get<int>(), 12);
  EXPECT_EQ(labelled.description["mesh_edges"]["boundary"].get<int>(), 0);
}

TEST(SurfaceMesh, AMeshWithoutAreaIsRefusedByName) {
  SurfaceMesh flat;
  flat.vertices = {Vec(0, 0, 0), Vec(1, 0, 0), Vec(2, 0, 0)};
  flat.triangles = {{0, 1, 2}};
  try {
    sample_mesh(flat, SampleParams{}, "flat.obj");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), "flat.obj");
  }
}

}  // namespace
}  // namespace glint::cad
