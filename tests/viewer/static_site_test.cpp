// The viewer's site (viewer/static_site.h): request paths that could leave the site are refused,
// missing files are clear errors, and the static copy is plain files, written whole.
#include "viewer/static_site.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/error.h"
#include "support/error_of.h"
#include "viewer_test_support.h"

namespace glint {
namespace {

namespace fs = std::filesystem;
using viewer::site_relative_path;

TEST(SiteRelativePath, DecodesPlainPaths) {
  EXPECT_EQ(site_relative_path("/"), "index.html");
  EXPECT_EQ(site_relative_path("/index.html?intrinsics=1,2#top"), "index.html");
  EXPECT_EQ(site_relative_path("/three/addons/loaders/GLTFLoader.js"),
            "three/addons/loaders/GLTFLoader.js");
  EXPECT_EQ(site_relative_path("/a%20b.js"), "a b.js");
  EXPECT_EQ(site_relative_path("/scene.glb"), "scene.glb");
}

TEST(SiteRelativePath, RefusesWhatCouldLeaveTheSite) {
  for (const char* target :
       {"", "index.html", "/../secret", "/three/../../secret", "/%2e%2e/secret", "/three/%2E%2E/x",
        "/..%2fsecret", "/./index.html", "/three//x.js", "/three/", "/a%5c..%5csecret", "/a%00b",
        "/a%zz", "/a%2", "http://host/index.html"})
    EXPECT_FALSE(site_relative_path(target).has_value()) << target;
}

TEST(ContentType, ByExtension) {
  EXPECT_EQ(viewer::content_type("a/index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(viewer::content_type("viewer.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(viewer::content_type("scene.glb"), "model/gltf-binary");
  EXPECT_EQ(viewer::content_type("x.bin"), "application/octet-stream");
}

class Site : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("glint_static_site_test_" +
               std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
               std::to_string(::getpid()));
    fs::remove_all(folder_);
    test::make_site_files(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }
  fs::path folder_;
};

TEST_F(Site, ResolvesPageFilesAndTheScene) {
  const viewer::StaticSite site(folder_ / "page", folder_ / "out" / "scene.glb");
  EXPECT_EQ(site.resolve("/"), folder_ / "page" / "index.html");
  EXPECT_EQ(site.resolve("/scene.glb"), folder_ / "out" / "scene.glb");
  EXPECT_EQ(site.resolve("/three/three.module.min.js"),
            folder_ / "page" / "three" / "three.module.min.js");
  EXPECT_FALSE(site.resolve("/missing.js"));
  EXPECT_FALSE(site.resolve("/three"));  // a folder, not a file
  test::write_text(folder_ / "secret", "secret");
  EXPECT_FALSE(site.resolve("/../secret"));
}

TEST_F(Site, MissingSceneOrPageFileIsAClearError) {
  const Error no_scene = test::error_of(
      [&] { viewer::StaticSite(folder_ / "page", folder_ / "elsewhere" / "scene.glb"); });
  EXPECT_EQ(no_scene.file(), (folder_ / "elsewhere" / "scene.glb").string());
  EXPECT_NE(no_scene.reason().find("no scene.glb"), std::string::npos) << no_scene.what();

  fs::remove(folder_ / "page" / "three" / "three.core.min.js");
  const Error incomplete =
      test::error_of([&] { viewer::StaticSite(folder_ / "page", folder_ / "out" / "scene.glb"); });
  EXPECT_NE(incomplete.file().find("three.core.min.js"), std::string::npos) << incomplete.what();
  EXPECT_NE(incomplete.reason().find("install-deps"), std::string::npos) << incomplete.what();
}

TEST_F(Site, StaticCopyHoldsPlainFilesAndReplacesOnlyAPreviousCopy) {
  // A link in the page folder (as in the build tree) is copied as the file it names.
  fs::remove(folder_ / "page" / "viewer.js");
  test::write_text(folder_ / "elsewhere.js", "linked");
  fs::create_symlink(folder_ / "elsewhere.js", folder_ / "page" / "viewer.js");
  const viewer::StaticSite site(folder_ / "page", folder_ / "out" / "scene.glb");
  const fs::path copy = folder_ / "copy";
  viewer::write_static_copy(site, copy);
  for (const char* file : viewer::kRequiredPageFiles)
    EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(copy / file))) << file;
  EXPECT_TRUE(fs::is_regular_file(copy / "scene.glb"));
  std::ifstream linked(copy / "viewer.js");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(linked), {}), "linked");

  viewer::write_static_copy(site, copy);  // a previous copy is replaced
  EXPECT_TRUE(fs::exists(copy / "index.html"));

  test::write_text(folder_ / "mine" / "notes.txt", "keep");
  const Error refused = test::error_of([&] { viewer::write_static_copy(site, folder_ / "mine"); });
  EXPECT_EQ(refused.file(), (folder_ / "mine").string());
  EXPECT_TRUE(fs::exists(folder_ / "mine" / "notes.txt"));
  for (const auto& entry : fs::directory_iterator(folder_))
    EXPECT_EQ(entry.path().string().find(".partial-"), std::string::npos) << entry.path();
}

}  // namespace
}  // namespace glint
