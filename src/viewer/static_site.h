#pragma once
// The files `glint view` serves: the viewer page's folder (core/resources.h web_directory():
// index.html, viewer.js, three/) at the site's root and a reconstruction's scene.glb beside it,
// and the self-contained static copy of the same site (`glint view OUT --write-html DIR`).
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace glint::viewer {

// The files the page needs to run, relative to the site's root; their absence means an
// incomplete installation (the three.js modules come from web/node_modules, installed by
// scripts/install-deps.sh).
inline constexpr const char* kRequiredPageFiles[] = {"index.html",
                                                     "viewer.js",
                                                     "three/three.module.min.js",
                                                     "three/three.core.min.js",
                                                     "three/addons/loaders/GLTFLoader.js",
                                                     "three/addons/controls/OrbitControls.js",
                                                     "three/addons/controls/TransformControls.js"};

// Decodes an HTTP request target's path ("/three/a%20b.js?x=1" -> "three/a b.js"): the query is
// dropped, %XX decoded, the leading '/' removed, "" becomes "index.html". Returns nothing for a
// path that could leave the site: a ".." or "." segment, a backslash, a NUL, a malformed %
// escape, an empty segment ("a//b") or a path not starting with '/'.
std::optional<std::string> site_relative_path(std::string_view request_target);

// The Content-Type of a file by its extension (text/html, text/javascript, model/gltf-binary,
// ...; application/octet-stream for others).
std::string content_type(const std::filesystem::path& file);

class StaticSite {
 public:
  // `page_folder` holds the page (kRequiredPageFiles); `scene_glb` is served as /scene.glb.
  // Throws glint::Error naming the missing file: scene.glb (the reconstruction has none) or a
  // page file (the installation is incomplete).
  StaticSite(std::filesystem::path page_folder, std::filesystem::path scene_glb);

  // The file behind a request target, or nothing (not found, or refused by
  // site_relative_path()). Only regular files (or links to them) are served.
  std::optional<std::filesystem::path> resolve(std::string_view request_target) const;

  const std::filesystem::path& page_folder() const { return page_folder_; }
  const std::filesystem::path& scene_glb() const { return scene_glb_; }

 private:
  std::filesystem::path page_folder_, scene_glb_;
};

// Writes the site as plain files into `folder` (links in the page folder are copied as the
// files they name), so any static file server can serve it. Written as FOLDER.partial-PID and
// renamed at the end; an existing `folder` is replaced only when it is empty or a previous copy
// (it has index.html and scene.glb), never another folder of the user's. Throws glint::Error.
void write_static_copy(const StaticSite& site, const std::filesystem::path& folder);

}  // namespace glint::viewer
