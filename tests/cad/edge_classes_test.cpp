// B-rep edge classes and the labels they give: fillets' tangent edges are smooth, the other
// edges of a box sharp; a cylinder cut open by a plane has a boundary on the cut only.
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRep_Tool.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <cmath>

#include "cad/part.h"
#include "cad/sample.h"
#include "core/error.h"

namespace glint::cad {
namespace {

// The box [0,10]^3 with its edge along z at x = y = 10 filleted with radius 2.
TopoDS_Shape box_with_one_fillet() {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(10.0, 10.0, 10.0).Shape();
  TopTools_IndexedMapOfShape edges;
  TopExp::MapShapes(box, TopAbs_EDGE, edges);
  BRepFilletAPI_MakeFillet fillet(box);
  for (int i = 1; i <= edges.Extent(); ++i) {
    const TopoDS_Edge edge = TopoDS::Edge(edges(i));
    const gp_Pnt a = BRep_Tool::Pnt(TopExp::FirstVertex(edge));
    const gp_Pnt b = BRep_Tool::Pnt(TopExp::LastVertex(edge));
    if (a.X() == 10.0 && b.X() == 10.0 && a.Y() == 10.0 && b.Y() == 10.0) fillet.Add(2.0, edge);
  }
  fillet.Build();
  EXPECT_TRUE(fillet.IsDone());
  return fillet.Shape();
}

TEST(EdgeClasses, BoxWithOneFilletedEdge) {
  const EdgeClasses classes = classify_edges(box_with_one_fillet(), 25.0, 1e-3);
  // 11 box edges stay sharp, the fillet's two end arcs meet the side faces at 90 degrees
  // (sharp), its two tangent lines are smooth.
  EXPECT_EQ(classes.sharp, 13);
  EXPECT_EQ(classes.smooth, 2);
  EXPECT_EQ(classes.boundary, 0);
  // Sharp length: 8 full edges of 10, 2 edges of 10 shortened by the radius at one end... all
  // edges touching the fillet lose 2: 4 of them (8 each), 7 untouched (10 each), 2 arcs (pi).
  EXPECT_NEAR(classes.sharp_length, 7 * 10.0 + 4 * 8.0 + 2 * M_PI, 1e-2);
}

TEST(EdgeClasses, FilletTangentLinesAreNotLabelledSharp) {
  SampleParams params;
  params.points = 60000;
  params.seed = 4;
  const LabelledCloud labelled = sample_shape(box_with_one_fillet(), params);
  const PointCloud& cloud = labelled.cloud;
  const auto& labels = *cloud.get<std::uint8_t>("label");
  const double spacing = labelled.description["median_spacing"].get<double>();
  int near_tangent = 0, near_sharp = 0, sharp_near_sharp = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double x = cloud.x[i], y = cloud.y[i], z = cloud.z[i];
    if (z < 1.0 || z > 9.0) continue;
    // The tangent lines (8, 10, z) and (10, 8, z).
    if (std::hypot(x - 8.0, y - 10.0) < 0.2 * spacing ||
        std::hypot(x - 10.0, y - 8.0) < 0.2 * spacing) {
      ++near_tangent;
      EXPECT_EQ(labels[i], 0) << x << " " << y << " " << z;
    }
    // The sharp edge (0, 0, z).
    if (std::hypot(x, y) < 0.2 * spacing) {
      ++near_sharp;
      sharp_near_sharp += labels[i] == 1;
    }
  }
  EXPECT_GT(near_tangent, 5);
  EXPECT_GT(near_sharp, 2);
  EXPECT_EQ(sharp_near_sharp, near_sharp);
}

TEST(EdgeClasses, CutCylinderHasItsBoundaryOnTheCutOnly) {
  const TopoDS_Shape cylinder = BRepPrimAPI_MakeCylinder(5.0, 10.0).Shape();
  const double point[3] = {0.0, 0.0, 4.0}, normal[3] = {0.0, 0.0, 1.0};
  const TopoDS_Shape cut = cut_open(cylinder, point, normal);
  const EdgeClasses classes = classify_edges(cut, 25.0, 1e-3);
  EXPECT_EQ(classes.boundary, 1);  // the circle at z = 4
  EXPECT_EQ(classes.sharp, 1);     // the top rim; the seam is no feature
  EXPECT_NEAR(classes.boundary_length, 2 * M_PI * 5.0, 1e-2);

  SampleParams params;
  params.points = 40000;
  params.seed = 2;
  const LabelledCloud labelled = sample_shape(cut, params);
  const PointCloud& cloud = labelled.cloud;
  const auto& labels = *cloud.get<std::uint8_t>("label");
  const double band = 0.6 * labelled.description["median_spacing"].get<double>();
  int boundary = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_GE(cloud.z[i], 4.0 - 1e-4);  // nothing below the cut, no cap
    if (labels[i] == 2) {
      ++boundary;
      EXPECT_LE(cloud.z[i], 4.0 + band + 1e-4);
    }
    if (cloud.z[i] < 4.0 + 0.3 * band) {
      EXPECT_EQ(labels[i], 2);
    }
    if (cloud.z[i] > 4.0 + band + 1e-3 && cloud.z[i] < 10.0 - band) {
      EXPECT_EQ(labels[i], 0);  // the side between cut and rim, the seam included
    }
  }
  EXPECT_GT(boundary, 50);
}

// Sharp points per unit edge length on a uniformly sampled box: each edge's two faces carry a
// strip of half-width band x spacing, so about N x 2 band spacing / area points per unit length.
TEST(EdgeClasses, SharpBandMatchesTheAnalyticEdgeLength) {
  const TopoDS_Shape box = BRepPrimAPI_MakeBox(1.0, 2.0, 3.0).Shape();
  SampleParams params;
  params.points = 100000;
  params.seed = 7;
  const LabelledCloud labelled = sample_shape(box, params);
  const double area = 2.0 * (1 * 2 + 1 * 3 + 2 * 3), edge_length = 4.0 * (1 + 2 + 3);
  const double spacing = std::sqrt(area / params.points);
  EXPECT_NEAR(labelled.description["median_spacing"].get<double>(), spacing, 1e-9);
  const double expected_per_length = params.points * 2.0 * params.band * spacing / area;
  const double measured_per_length =
      labelled.description["labels"]["sharp-edge"].get<double>() / edge_length;
  EXPECT_NEAR(measured_per_length / expected_per_length, 1.0, 0.08)
      << measured_per_length << " vs " << expected_per_length;
}

// A plane without edges has no bounding box (OCCT reports ±1e100): one clear error, not a
// crash on an empty sample (the generator redraws such a part).
TEST(EdgeClasses, UnboundedFaceIsRejectedForEverySampling) {
  const TopoDS_Shape plane = BRepBuilderAPI_MakeFace(gp_Pln(gp::Origin(), gp::DZ())).Shape();
  for (const Sampling sampling : {Sampling::vertices, Sampling::uniform, Sampling::scan}) {
    SampleParams params;
    params.sampling = sampling;
    try {
      sample_shape(plane, params);
      ADD_FAILURE() << "an unbounded face was sampled";
    } catch (const Error& e) {
      EXPECT_EQ(e.element(), "bounding box");
    }
  }
}

}  // namespace
}  // namespace glint::cad
