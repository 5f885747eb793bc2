// scene.glb: a unit cube with a known material and light round-trips through the exporter and
// the GLB reader (structure, metres, the root's axis conversion, light units, material values,
// _SEGMENT, the atlas), the triangle budget, reconstruction folders and bad inputs; the Khronos
// validator on the written file, and `glint export` end to end.
#include "gltf/scene_export.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "fusion/triangle_mesh.h"
#include "gltf/material_conversion.h"
#include "io/json_report.h"
#include "render/sensor.h"
#include "support/cli_fixture.h"

namespace glint::gltf {
namespace {

namespace fs = std::filesystem;

// Cube [x0, x0 + 1] x [0, 1] x [0, 1], outward counter-clockwise faces, all of `segment`.
void add_cube(Reconstruction& scene, float x0, int segment, const Eigen::Vector3f& kd) {
  const int base = int(scene.vertices.size());
  for (int i = 0; i < 8; ++i) {
    scene.vertices.push_back({x0 + float(i & 1), float(i >> 1 & 1), float(i >> 2 & 1)});
    scene.kd.push_back(kd);
    scene.segment.push_back(segment);
  }
  const int faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                            {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) scene.triangles.push_back({base + f[0], base + f[1], base + f[2]});
}

// Segment 1: a cube with a Ward material (kd 0.6 0.5 0.4, ks 0.05 0.04 0.03, alpha 0.1); segment
// 2: a cube materials.json does not know; one light at (0.5, 3, 0.5) of intensity (8, 4, 2).
Reconstruction cube_scene() {
  Reconstruction scene;
  add_cube(scene, 0, 1, {0.6f, 0.5f, 0.4f});
  add_cube(scene, 2, 2, {0.2f, 0.2f, 0.2f});
  scene.materials = {{"exposure", 0.5},
                     {"segments",
                      {{{"id", 1},
                        {"kd", {0.6, 0.5, 0.4}},
                        {"ks", {0.05, 0.04, 0.03}},
                        {"alpha", 0.1},
                        {"estimates", 7}}}}};
  render::PointLight light;
  light.position = {0.5, 3, 0.5};
  light.intensity = {8, 4, 2};
  scene.lights.lights = {light};
  return scene;
}

Glb round_trip(const Reconstruction& scene, const ExportParams& params) {
  const std::vector<std::uint8_t> bytes = build_scene_glb(scene, params).bytes();
  return parse_glb(bytes, "memory");
}

const nlohmann::json& primitive_of(const Glb& glb, int segment) {
  for (const nlohmann::json& p : glb.document["meshes"][0]["primitives"])
    if (glb.document["materials"][int(p["material"])]["extras"]["segment"] == segment) return p;
  throw std::runtime_error("no primitive for the segment");
}

Eigen::Quaternionf root_rotation(const Glb& glb) {
  const nlohmann::json& root = glb.document["nodes"][0];
  if (!root.contains("rotation")) return Eigen::Quaternionf::Identity();
  const nlohmann::json& q = root["rotation"];
  return Eigen::Quaternionf(q[3], q[0], q[1], q[2]);
}

TEST(SceneExport, CubeRoundTripsStructureUnitsMaterialsAndLights) {
  const Glb glb = round_trip(cube_scene(), {.texture_size = 64});
  const nlohmann::json& doc = glb.document;
  EXPECT_EQ(doc["scene"], 0);
  EXPECT_EQ(doc["nodes"][0]["name"], "glint_world");
  EXPECT_EQ(doc["nodes"][0]["children"], nlohmann::json({1, 2}));
  EXPECT_EQ(doc["nodes"][1]["mesh"], 0);
  ASSERT_EQ(doc["meshes"][0]["primitives"].size(), 2u);

  // Metres: the cube of segment 1 spans [0, 1]^3, its 12 triangles, _SEGMENT = 1 throughout.
  const nlohmann::json& cube = primitive_of(glb, 1);
  const nlohmann::json& position = doc["accessors"][int(cube["attributes"]["POSITION"])];
  EXPECT_EQ(position["min"], nlohmann::json({0, 0, 0}));
  EXPECT_EQ(position["max"], nlohmann::json({1, 1, 1}));
  EXPECT_EQ(doc["accessors"][int(cube["indices"])]["count"], 36);
  for (const double s : accessor_values(glb, cube["attributes"]["_SEGMENT"])) EXPECT_EQ(s, 1);
  // Normals point out of the cube (away from its centre).
  const std::vector<double> p = accessor_values(glb, cube["attributes"]["POSITION"]);
  const std::vector<double> n = accessor_values(glb, cube["attributes"]["NORMAL"]);
  for (std::size_t i = 0; i < p.size(); i += 3) {
    const Eigen::Vector3d offset(p[i] - 0.5, p[i + 1] - 0.5, p[i + 2] - 0.5);
    EXPECT_GT(offset.dot(Eigen::Vector3d(n[i], n[i + 1], n[i + 2])), 0.0);
  }

  // The material: metallic 0, roughness from alpha, F0 = ks, Ward values in extras.
  const nlohmann::json& material = doc["materials"][int(cube["material"])];
  EXPECT_EQ(material["name"], "segment_1");
  EXPECT_EQ(material["pbrMetallicRoughness"]["metallicFactor"], 0.0);
  EXPECT_NEAR(material["pbrMetallicRoughness"]["roughnessFactor"].get<double>(),
              std::sqrt(kWardToGgx * 0.1), 1e-6);
  EXPECT_EQ(material["pbrMetallicRoughness"]["baseColorTexture"]["index"], 0);
  const nlohmann::json& specular = material["extensions"]["KHR_materials_specular"];
  EXPECT_NEAR(specular["specularColorFactor"][0].get<double>() * kDielectricF0, 0.05, 1e-6);
  EXPECT_NEAR(specular["specularColorFactor"][2].get<double>() * kDielectricF0, 0.03, 1e-6);
  EXPECT_EQ(material["extras"]["ward"]["alpha"], 0.1);
  EXPECT_EQ(material["extras"]["ward"]["kd"], nlohmann::json({0.6, 0.5, 0.4}));
  EXPECT_EQ(material["extras"]["estimates"], 7);
  // The cube without a material: no specular, fully rough.
  const nlohmann::json& other = doc["materials"][int(primitive_of(glb, 2)["material"])];
  EXPECT_EQ(other["extensions"]["KHR_materials_specular"]["specularFactor"], 0.0);
  EXPECT_EQ(other["pbrMetallicRoughness"]["roughnessFactor"], 1.0);

  // The light: colour x candela = glint's intensity, at its position under the root.
  const nlohmann::json& light = doc["extensions"]["KHR_lights_punctual"]["lights"][0];
  EXPECT_EQ(light["type"], "point");
  EXPECT_EQ(light["intensity"], 8.0);
  EXPECT_EQ(light["color"], nlohmann::json({1.0, 0.5, 0.25}));
  const nlohmann::json& node = doc["nodes"][2];
  EXPECT_EQ(node["extensions"]["KHR_lights_punctual"]["light"], 0);
  EXPECT_EQ(node["translation"], nlohmann::json({0.5, 3.0, 0.5}));
  EXPECT_EQ(doc["scenes"][0]["extras"]["glint"]["exposure"], 0.5);
  EXPECT_EQ(doc["extensionsUsed"],
            nlohmann::json({"KHR_materials_specular", "KHR_lights_punctual"}));
}

TEST(SceneExport, AtlasHoldsTheAlbedoAsSrgb) {
  const Glb glb = round_trip(cube_scene(), {.texture_size = 64});
  const nlohmann::json& doc = glb.document;
  const nlohmann::json& view = doc["bufferViews"][int(doc["images"][0]["bufferView"])];
  EXPECT_EQ(doc["images"][0]["mimeType"], "image/png");
  const std::vector<std::uint8_t> png(
      glb.bin.begin() + int(view["byteOffset"]),
      glb.bin.begin() + int(view["byteOffset"]) + int(view["byteLength"]));
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_COLOR);
  ASSERT_EQ(image.cols, 64);
  // At every vertex of cube 1, the texel under its UV is kd (0.6, 0.5, 0.4) in sRGB.
  const nlohmann::json& cube = primitive_of(glb, 1);
  const std::vector<double> uv = accessor_values(glb, cube["attributes"]["TEXCOORD_0"]);
  for (std::size_t i = 0; i < uv.size(); i += 2) {
    const cv::Vec3b bgr = image.at<cv::Vec3b>(int(uv[i + 1] * 64), int(uv[i] * 64));
    EXPECT_EQ(bgr[2], fusion::linear_to_srgb8(0.6f));
    EXPECT_EQ(bgr[1], fusion::linear_to_srgb8(0.5f));
    EXPECT_EQ(bgr[0], fusion::linear_to_srgb8(0.4f));
  }
  // The per-vertex albedo rides along as _ALBEDO (COLOR_0 would multiply the texture).
  EXPECT_FALSE(cube["attributes"].contains("COLOR_0"));
  EXPECT_EQ(accessor_values(glb, cube["attributes"]["_ALBEDO"])[0], 0.6f);
}

TEST(SceneExport, WithoutTextureColor0IsTheLinearAlbedo) {
  const Glb glb = round_trip(cube_scene(), {.texture_size = 0});
  EXPECT_FALSE(glb.document.contains("images"));
  const nlohmann::json& cube = primitive_of(glb, 1);
  EXPECT_FALSE(cube["attributes"].contains("TEXCOORD_0"));
  const std::vector<double> colour = accessor_values(glb, cube["attributes"]["COLOR_0"]);
  EXPECT_EQ(colour[0], 0.6f);
  EXPECT_EQ(colour[2], 0.4f);
}

TEST(SceneExport, RootNodeTurnsTheUpAxisIntoGltfY) {
  for (const char* name : {"+x", "-x", "+y", "-y", "+z", "-z"}) {
    const UpAxis up = parse_up_axis(name);
    const Glb glb = round_trip(cube_scene(), {.texture_size = 0, .up = up});
    const Eigen::Quaternionf q = root_rotation(glb);
    EXPECT_NEAR(q.norm(), 1.0f, 1e-6f) << name;  // a rotation: lengths and handedness kept
    const Eigen::Vector3f axis =
        Eigen::Vector3f::Unit(std::string("xyz").find(name[1])) * (name[0] == '-' ? -1.0f : 1.0f);
    EXPECT_TRUE((q * axis).isApprox(Eigen::Vector3f::UnitY(), 1e-6f)) << name;
    EXPECT_EQ(glb.document["nodes"][0]["extras"]["up"], name);
  }
  // 7-Scenes-like worlds (+y down): the half turn about x also turns z, keeping handedness.
  const Eigen::Quaternionf q = world_to_gltf(UpAxis::neg_y);
  EXPECT_TRUE((q * Eigen::Vector3f::UnitZ()).isApprox(-Eigen::Vector3f::UnitZ(), 1e-6f));
  EXPECT_THROW(parse_up_axis("up"), Error);
}

TEST(SceneExport, SimplifiesToTheTriangleBudget) {
  Reconstruction scene = cube_scene();
  scene.triangles.clear();
  scene.vertices.clear();
  scene.kd.clear();
  scene.segment.clear();
  // A 40 x 40 grid of quads on a gentle bump: 3200 triangles.
  const int n = 40;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / n, z = float(j) / n;
      scene.vertices.push_back({x, 0.05f * std::sin(3 * x) * std::cos(2 * z), z});
      scene.kd.push_back({0.5f, 0.5f, 0.5f});
      scene.segment.push_back(1);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      scene.triangles.push_back({a, d, b});
      scene.triangles.push_back({a, c, d});
    }
  ExportStats stats;
  build_scene_glb(scene, {.mesh_triangles = 300, .texture_size = 64}, &stats);
  EXPECT_EQ(stats.input_triangles, 3200u);
  EXPECT_LE(stats.triangles, 300u);
  EXPECT_GT(stats.triangles, 100u);
  build_scene_glb(scene, {.mesh_triangles = 0, .texture_size = 64}, &stats);
  EXPECT_EQ(stats.triangles, 3200u);  // 0: full resolution
}

class SceneExportFiles : public CliTest {
 protected:
  // A reconstruction folder as `glint reconstruct` writes it.
  std::string write_folder(const Reconstruction& scene) {
    const std::string folder = path("recon");
    fusion::TriangleMesh mesh;
    mesh.vertices = scene.vertices;
    mesh.triangles = scene.triangles;
    mesh.colours = scene.kd;
    std::array<std::vector<float>, 4> columns;
    for (std::size_t i = 0; i < scene.vertices.size(); ++i) {
      for (int c = 0; c < 3; ++c) columns[c].push_back(scene.kd[i][c]);
      columns[3].push_back(float(scene.segment[i]));
    }
    const char* names[] = {"kd_r", "kd_g", "kd_b", "scalar_segment"};
    for (int k = 0; k < 4; ++k) mesh.vertex_properties.emplace_back(names[k], columns[k]);
    if (!scene.observations.empty())
      mesh.vertex_properties.emplace_back("observations", scene.observations);
    fusion::write_mesh_ply(folder + "/mesh.ply", mesh);
    io::write_json(folder + "/materials.json", scene.materials);
    reflectance::write_lights_json(folder + "/lights.json", scene.lights);
    return folder;
  }
};

TEST_F(SceneExportFiles, FolderReadsBackAsWritten) {
  const Reconstruction scene = cube_scene();
  const Reconstruction read = read_reconstruction(write_folder(scene));
  ASSERT_EQ(read.vertices.size(), scene.vertices.size());
  EXPECT_EQ(read.triangles, scene.triangles);
  EXPECT_EQ(read.segment, scene.segment);
  EXPECT_TRUE(read.kd[3].isApprox(scene.kd[3]));
  EXPECT_EQ(read.lights.lights.size(), 1u);
  EXPECT_TRUE(read.observations.empty());  // an older reconstruction's mesh
  EXPECT_FLOAT_EQ(read.observation_voxel_m, 0.02f);
  EXPECT_EQ(build_scene_glb(read, {.texture_size = 64}).bytes(),
            build_scene_glb(scene, {.texture_size = 64}).bytes());
}

TEST_F(SceneExportFiles, BadFoldersAreRefusedWithTheFileNamed) {
  EXPECT_THROW(read_reconstruction(path("missing")), Error);
  const std::string folder = write_folder(cube_scene());
  fs::remove(folder + "/lights.json");
  try {
    read_reconstruction(folder);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(e.file().find("lights.json"), std::string::npos);
  }
  // A mesh without glint's material properties.
  fusion::TriangleMesh plain;
  plain.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  plain.triangles = {{0, 1, 2}};
  fusion::write_mesh_ply(folder + "/mesh.ply", plain);
  reflectance::write_lights_json(folder + "/lights.json", cube_scene().lights);
  EXPECT_THROW(read_reconstruction(folder), Error);
}

TEST_F(SceneExportFiles, KhronosValidatorReportsNoErrorsOrWarnings) {
  const fs::path source = fs::path(GLINT_TEST_DATA_DIR).parent_path().parent_path();
  const char* web_env = std::getenv("GLINT_WEB_DIR");
  const fs::path web = web_env ? fs::path(web_env) : source / "web";
  if (std::system("node --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "node is not installed";
  if (!fs::exists(web / "node_modules" / "gltf-validator"))
    GTEST_SKIP() << "no " << (web / "node_modules").string() << " (scripts/install-deps.sh)";
  for (const int texture : {64, 0}) {
    const std::string glb = path("cube-" + std::to_string(texture) + ".glb");
    write_scene_glb(cube_scene(), {.texture_size = texture}, glb);
    const std::string log = path("validator.log");
    const std::string command = "GLINT_WEB_DIR='" + web.string() + "' node '" +
                                (source / "scripts" / "validate-glb.cjs").string() + "' '" + glb +
                                "' > '" + log + "' 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream stream(log);
    const std::string output(std::istreambuf_iterator<char>(stream), {});
    EXPECT_EQ(WEXITSTATUS(status), 0) << output;
    EXPECT_NE(output.find("0 errors, 0 warnings"), std::string::npos) << output;
  }
}

TEST_F(SceneExportFiles, ExportCommandWritesTheGlbAndReport) {
  const std::string folder = write_folder(cube_scene());
  const CommandResult ok = glint("export " + folder + " -o " + path("out/scene.glb") +
                                 " --texture-size 64 --up -y --report " + path("r.json"));
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const Glb glb = read_glb(path("out/scene.glb"));
  EXPECT_TRUE(root_rotation(glb).isApprox(world_to_gltf(UpAxis::neg_y)));
  const nlohmann::json report = io::read_json(path("r.json"));
  EXPECT_EQ(report["triangles"], 24);
  EXPECT_EQ(report["bytes"], fs::file_size(path("out/scene.glb")));
  const CommandResult bad = glint("export " + folder + " -o " + path("x.glb") + " --up sideways");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--up"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(path("x.glb")));
  const CommandResult no_steps =
      glint("export " + folder + " -o " + path("x.glb") + " --denoise-iterations 0");
  EXPECT_NE(no_steps.exit_code, 0);
  EXPECT_NE(no_steps.output.find("--denoise-iterations: must be more than 0, got 0"),
            std::string::npos)
      << no_steps.output;
  EXPECT_FALSE(fs::exists(path("x.glb")));
}

// A 0.8 m square of 2 cm quads with kd 0.5: its left half seen 30 times (kd within 0.005), its
// right half twice (kd off by up to 0.3, per vertex).
Reconstruction half_observed_plane() {
  Reconstruction scene;
  const int n = 40;
  std::uint32_t state = 12345;
  const auto uniform = [&state] {  // a fixed sequence in [-1, 1]
    state = state * 1664525u + 1013904223u;
    return float(state >> 8) / float(1 << 23) - 1.0f;
  };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      scene.vertices.push_back({0.02f * float(i), 0.02f * float(j), 0});
      const bool well = i < n / 2;
      scene.kd.push_back(Eigen::Vector3f::Constant(0.5f + (well ? 0.005f : 0.3f) * uniform()));
      scene.segment.push_back(1);
      scene.observations.push_back(well ? 30.0f : 2.0f);
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      scene.triangles.push_back({a, b, d});
      scene.triangles.push_back({a, d, c});
    }
  scene.materials = {
      {"exposure", 1.0}, {"observation_voxel_m", 0.02}, {"segments", nlohmann::json::array()}};
  return scene;
}

// Mean |kd - 0.5| over the atlas's non-empty texels (linear).
double mean_deviation(const Glb& glb) {
  const nlohmann::json& doc = glb.document;
  const nlohmann::json& view = doc["bufferViews"][int(doc["images"][0]["bufferView"])];
  const std::vector<std::uint8_t> png(
      glb.bin.begin() + int(view["byteOffset"]),
      glb.bin.begin() + int(view["byteOffset"]) + int(view["byteLength"]));
  const cv::Mat image = cv::imdecode(png, cv::IMREAD_COLOR);
  double sum = 0;
  int count = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b bgr = image.at<cv::Vec3b>(y, x);
      if (bgr[1] == 0) continue;
      sum += std::abs(render::srgb_to_linear(bgr[1] / 255.0f) - 0.5);
      ++count;
    }
  return count > 0 ? sum / count : 1.0;
}

TEST(SceneExport, DenoisingTheAlbedoNeedsTheObservationCounts) {
  try {
    build_scene_glb(cube_scene(), {.texture_size = 64, .denoise_albedo = true});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.element(), "observations");
  }
}

TEST_F(SceneExportFiles, DenoisedAlbedoIsCloserToTheTruthWhereItWasSeenRarely) {
  const std::string folder = write_folder(half_observed_plane());
  const std::string common = "export " + folder + " --mesh-triangles 0 --texture-size 128";
  const CommandResult plain = glint(common + " -o " + path("plain.glb"));
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  const CommandResult denoised = glint(common + " --denoise-albedo --denoise-iterations 300 -o " +
                                       path("denoised.glb") + " --report " + path("r.json"));
  ASSERT_EQ(denoised.exit_code, 0) << denoised.output;
  const double before = mean_deviation(read_glb(path("plain.glb")));
  const double after = mean_deviation(read_glb(path("denoised.glb")));
  EXPECT_GT(before, 0.02);
  EXPECT_LT(after, before);
  const nlohmann::json report = io::read_json(path("r.json"));
  EXPECT_EQ(report["albedo"]["denoising"]["iterations"], 300);
  EXPECT_FLOAT_EQ(report["albedo"]["denoising"]["texels_per_metre"].get<float>(), 50.0f);
}

}  // namespace
}  // namespace glint::gltf
