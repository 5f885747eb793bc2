// The kd atlas: charts by normal axis and group, packing without overlap, and seams that
// bilinear filtering never sees (every texel it reads inside a chart is baked from that chart).
#include "gltf/texture_atlas.h"

#include <gtest/gtest.h>

#include <random>

#include "core/error.h"

namespace glint::gltf {
namespace {

// A grid of n x n quads on the plane through `origin` spanned by `u`, `v` (metres), wound so the
// normal is u x v.
void add_grid(std::vector<Eigen::Vector3f>& vertices, std::vector<Eigen::Vector3i>& triangles,
              const Eigen::Vector3f& origin, const Eigen::Vector3f& u, const Eigen::Vector3f& v,
              int n) {
  const int base = int(vertices.size());
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      vertices.push_back(origin + u * (float(i) / n) + v * (float(j) / n));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      triangles.push_back({a, b, d});
      triangles.push_back({a, d, c});
    }
}

// Bilinear lookup as a glTF viewer does it (LINEAR filter, clamp to edge).
Eigen::Vector3f bilinear(const ImageF& image, const Eigen::Vector2f& uv) {
  const float x = uv.x() * image.width() - 0.5f, y = uv.y() * image.height() - 0.5f;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const float fx = x - x0, fy = y - y0;
  Eigen::Vector3f value = Eigen::Vector3f::Zero();
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const int px = std::clamp(x0 + dx, 0, image.width() - 1);
      const int py = std::clamp(y0 + dy, 0, image.height() - 1);
      const float w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy);
      for (int c = 0; c < 3; ++c) value[c] += w * image.at(px, py, c);
    }
  return value;
}

TEST(TextureAtlas, ChartsFollowNormalAxisAndGroup) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  // A floor facing +y (x cross -z... u = z, v = x gives +y) and a wall facing +x, sharing no edge,
  // and a second floor in another group.
  add_grid(vertices, triangles, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 4);
  add_grid(vertices, triangles, {2, 0, 0}, {0, 1, 0}, {0, 0, 1}, 4);
  add_grid(vertices, triangles, {0, 0, 3}, {0, 0, 1}, {1, 0, 0}, 4);
  std::vector<int> group(triangles.size(), 0);
  std::fill(group.begin() + 64, group.end(), 1);
  const AtlasLayout layout = layout_atlas(vertices, triangles, group, {.size = 256});
  EXPECT_EQ(layout.charts, 3);
  EXPECT_GT(layout.texels_per_metre, 20.0f);
  // Each chart keeps the density: a 1 m edge spans texels_per_metre texels.
  const Eigen::Vector3i& first = layout.triangles[0];
  const float edge_texels = (layout.uv[first[1]] - layout.uv[first[0]]).norm() * layout.size;
  EXPECT_NEAR(edge_texels, layout.texels_per_metre * 0.25f, 1e-3f);
}

TEST(TextureAtlas, BilinearLookupsInsideChartsReadOnlyTheirOwnBakedTexels) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  add_grid(vertices, triangles, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 6);  // +y floor
  add_grid(vertices, triangles, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, 6);  // +x wall, shares an edge
  add_grid(vertices, triangles, {0, 1, 0}, {0.01f, 0, 0}, {0, 0, 0.01f}, 1);  // a 1 cm sliver chart
  std::vector<int> group(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) group[t] = int(t / 72);
  AtlasLayout layout = layout_atlas(vertices, triangles, group, {.size = 64});
  ASSERT_EQ(layout.charts, 3);
  // Each chart one colour: a lookup anywhere inside a chart must give exactly that colour, never
  // the black of an unbaked texel or another chart's.
  const auto colour = [&](int t) {
    return Eigen::Vector3f(group[t] == 0, group[t] == 1, group[t] == 2);
  };
  const ImageF image = bake_atlas(
      layout, vertices, [&](const Eigen::Vector3f&, int t) { return colour(t); }, {.size = 64});
  EXPECT_EQ(layout.overlapping_texels, 0u);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(0, 1);
  for (int t = 0; t < int(layout.triangles.size()); ++t)
    for (int k = 0; k < 20; ++k) {
      float a = unit(random), b = unit(random);
      if (a + b > 1) a = 1 - a, b = 1 - b;
      const Eigen::Vector3i& f = layout.triangles[t];
      const Eigen::Vector2f uv =
          (1 - a - b) * layout.uv[f[0]] + a * layout.uv[f[1]] + b * layout.uv[f[2]];
      ASSERT_TRUE(bilinear(image, uv).isApprox(colour(t), 1e-5f)) << "triangle " << t;
    }
}

TEST(TextureAtlas, BakesTheSurfaceUnderEachTexel) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  add_grid(vertices, triangles, {0, 0, 0}, {0, 0, 1}, {1, 0, 0}, 3);
  AtlasLayout layout =
      layout_atlas(vertices, triangles, std::vector<int>(triangles.size(), 0), {.size = 128});
  const auto field = [](const Eigen::Vector3f& p) { return Eigen::Vector3f(p.x(), p.z(), 0.5f); };
  const ImageF image = bake_atlas(
      layout, vertices, [&](const Eigen::Vector3f& p, int) { return field(p); }, {.size = 128});
  // A linear field comes back to within the slope times a texel.
  const float texel_m = 1.0f / layout.texels_per_metre;
  for (std::size_t v = 0; v < layout.uv.size(); ++v) {
    const Eigen::Vector3f expected = field(vertices[layout.source_vertex[v]]);
    EXPECT_LT((bilinear(image, layout.uv[v]) - expected).cwiseAbs().maxCoeff(), 1.5f * texel_m);
  }
}

TEST(TextureAtlas, RefusesALayoutThatCannotFit) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  for (int i = 0; i < 200; ++i)  // 200 separate charts, 10 m apart
    add_grid(vertices, triangles, {10.0f * i, 0, 0}, {0, 0, 1}, {1, 0, 0}, 1);
  EXPECT_THROW(
      layout_atlas(vertices, triangles, std::vector<int>(triangles.size(), 0), {.size = 16}),
      Error);
  EXPECT_THROW(
      layout_atlas(vertices, triangles, std::vector<int>(triangles.size(), 0), {.size = 4}), Error);
}

}  // namespace
}  // namespace glint::gltf
