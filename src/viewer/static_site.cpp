#include "viewer/static_site.h"

#include <unistd.h>

#include <array>
#include <system_error>

#include "core/error.h"

namespace glint::viewer {
namespace fs = std::filesystem;
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool is_file(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);  // follows links
}

}  // namespace

std::optional<std::string> site_relative_path(std::string_view request_target) {
  if (request_target.empty() || request_target.front() != '/') return std::nullopt;
  request_target = request_target.substr(0, request_target.find_first_of("?#"));
  std::string decoded;
  decoded.reserve(request_target.size());
  for (std::size_t i = 1; i < request_target.size(); ++i) {
    char c = request_target[i];
    if (c == '%') {
      if (i + 2 >= request_target.size()) return std::nullopt;
      const int high = hex_digit(request_target[i + 1]), low = hex_digit(request_target[i + 2]);
      if (high < 0 || low < 0) return std::nullopt;
      c = char(high * 16 + low);
      i += 2;
    }
    if (c == '\0' || c == '\\') return std::nullopt;
    decoded += c;
  }
  if (decoded.empty()) return "index.html";
  // Every segment must be a plain name: no "..", ".", or empty segment (a '/' at either end).
  std::size_t start = 0;
  while (true) {
    const std::size_t end = decoded.find('/', start);
    const std::string_view segment =
        std::string_view(decoded).substr(start, end == std::string::npos ? end : end - start);
    if (segment.empty() || segment == "." || segment == "..") return std::nullopt;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return decoded;
}

std::string content_type(const fs::path& file) {
  static const std::array<std::pair<const char*, const char*>, 8> types{{
      {".html", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".glb", "model/gltf-binary"},
      {".png", "image/png"},
      {".txt", "text/plain; charset=utf-8"},
      {"", "text/plain; charset=utf-8"},  // LICENSE
  }};
  const std::string extension = file.extension().string();
  for (const auto& [suffix, type] : types)
    if (extension == suffix) return type;
  return "application/octet-stream";
}

StaticSite::StaticSite(fs::path page_folder, fs::path scene_glb)
    : page_folder_(std::move(page_folder)), scene_glb_(std::move(scene_glb)) {
  if (!is_file(scene_glb_))
    throw Error(scene_glb_.string(), "",
                "no scene.glb here (glint reconstruct writes OUT/scene.glb; glint export makes "
                "one from a kept reconstruction)");
  for (const char* file : kRequiredPageFiles)
    if (!is_file(page_folder_ / file))
      throw Error((page_folder_ / file).string(), "",
                  "the viewer page is incomplete (the three.js modules come from web/node_modules: "
                  "run scripts/install-deps.sh, then cmake again; or set GLINT_WEB_DIR)");
}

std::optional<fs::path> StaticSite::resolve(std::string_view request_target) const {
  const std::optional<std::string> relative = site_relative_path(request_target);
  if (!relative) return std::nullopt;
  if (*relative == "scene.glb") return scene_glb_;
  fs::path file = page_folder_ / *relative;
  if (!is_file(file)) return std::nullopt;
  return file;
}

void write_static_copy(const StaticSite& site, const fs::path& folder) {
  std::error_code error;
  if (fs::exists(folder, error)) {
    const bool empty = fs::is_directory(folder, error) && fs::is_empty(folder, error);
    const bool previous_copy = is_file(folder / "index.html") && is_file(folder / "scene.glb");
    if (!empty && !previous_copy)
      throw Error(folder.string(), "",
                  "exists and is not a previous viewer copy (index.html and scene.glb); not "
                  "replaced");
  }
  const fs::path partial = fs::path(folder.string() + ".partial-" + std::to_string(::getpid()));
  fs::remove_all(partial, error);
  try {
    fs::create_directories(partial);
    for (auto entry = fs::recursive_directory_iterator(site.page_folder());
         entry != fs::recursive_directory_iterator(); ++entry) {
      const fs::path target = partial / entry->path().lexically_relative(site.page_folder());
      if (entry->is_directory())
        fs::create_directories(target);
      else if (entry->is_regular_file())  // links are followed: the file's content is copied
        fs::copy_file(entry->path(), target);
    }
    fs::copy_file(site.scene_glb(), partial / "scene.glb", fs::copy_options::overwrite_existing);
    fs::remove_all(folder);
    fs::rename(partial, folder);
  } catch (const fs::filesystem_error& failure) {
    fs::remove_all(partial, error);
    throw Error(failure.path1().empty() ? folder.string() : failure.path1().string(), "",
                "cannot write the viewer copy: " + failure.code().message());
  }
}

}  // namespace glint::viewer
