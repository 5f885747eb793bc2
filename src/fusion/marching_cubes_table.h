#pragma once
// Marching-cubes case table (Lorensen & Cline 1987), generated at start-up instead of typed in:
// for each of the 256 inside/outside configurations of a cube's corners, the iso-surface
// polygons are traced face by face and fanned into triangles. Ambiguous faces separate the
// inside corners, a rule that depends on the face alone, so neighbouring cubes agree and the
// surface is watertight. Triangles wind counter-clockwise seen from outside (positive SDF).
//
// Corner c sits at (c & 1, (c >> 1) & 1, (c >> 2) & 1); corner c is inside when bit c of the
// configuration is set. Edge e runs from corner kCubeEdges[e].corner along axis
// kCubeEdges[e].axis (0 = x, 1 = y, 2 = z) to the next corner.
#include <array>
#include <cstdint>

namespace glint::fusion {

struct CubeEdge {
  int corner;
  int axis;
};
inline constexpr std::array<CubeEdge, 12> kCubeEdges{{{0, 0},
                                                      {2, 0},
                                                      {4, 0},
                                                      {6, 0},
                                                      {0, 1},
                                                      {1, 1},
                                                      {4, 1},
                                                      {5, 1},
                                                      {0, 2},
                                                      {1, 2},
                                                      {2, 2},
                                                      {3, 2}}};

struct CubeCase {
  std::uint8_t triangle_count = 0;
  std::array<std::int8_t, 36> edges{};  // 3 edge ids per triangle
};

// The 256 cases, indexed by configuration.
const std::array<CubeCase, 256>& marching_cubes_cases();

}  // namespace glint::fusion
