// glint.denoise: the noise-level map and guidance map, and the denoising methods of
// `glint denoise noise-map` and `glint denoise run`, on NumPy images.
#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <functional>
#include <map>

#include "bindings.h"
#include "core/error.h"
#include "denoise/denoiser.h"
#include "denoise/noise_level.h"
#include "numpy_support.h"

namespace glint::python {
namespace {

py::tuple noise_map(const py::object& image_arg, const std::string& method, int patch, int bins,
                    double upper_quantile) {
  const ImageF image = image_from_array(image_arg, "image");
  // The CLI's option checks (--bins 8..65536, --upper-quantile 0.5..1).
  if (bins < 8 || bins > 65536) throw Error("bins", "", "must be in 8..65536");
  if (!(upper_quantile >= 0.5 && upper_quantile <= 1.0))
    throw Error("upper_quantile", "", "must be in 0.5..1");
  ImageF noise;
  denoise::Guidance guidance;
  {
    py::gil_scoped_release release;
    noise = denoise::noise_level(image, {denoise::parse_noise_method(method), patch});
    guidance = denoise::guidance_from_noise(noise, {bins, upper_quantile});
  }
  py::dict info;
  info["n_peak"] = guidance.n_peak;
  info["lower"] = guidance.lower;
  info["upper"] = guidance.upper;
  return py::make_tuple(array_from_image(std::move(guidance.map)),
                        array_from_image(std::move(noise)), info);
}

// Sets `target` from a keyword value; None leaves it unset (the preset's value).
template <class T>
void set_optional(std::optional<T>& target, const py::handle& value) {
  if (!value.is_none()) target = value.cast<T>();
}

// The CLI's denoiser options by their Python names ('_' for '-'; --lr, --pd as they are).
denoise::DenoiserSettings settings_from(const py::dict& options) {
  denoise::DenoiserSettings s;
  using Setter = std::function<void(const py::handle&)>;
  const std::map<std::string, Setter> setters{
      {"config", [&](const py::handle& v) { s.config = v.cast<std::string>(); }},
      {"device", [&](const py::handle& v) { s.device = v.cast<std::string>(); }},
      {"seed", [&](const py::handle& v) { s.seed = v.cast<std::uint64_t>(); }},
      {"iterations", [&](const py::handle& v) { set_optional(s.iterations, v); }},
      {"predictions", [&](const py::handle& v) { set_optional(s.predictions, v); }},
      {"levels", [&](const py::handle& v) { set_optional(s.levels, v); }},
      {"channels", [&](const py::handle& v) { set_optional(s.channels, v); }},
      {"lr", [&](const py::handle& v) { set_optional(s.learning_rate, v); }},
      {"input_noise", [&](const py::handle& v) { set_optional(s.input_noise, v); }},
      {"average", [&](const py::handle& v) { set_optional(s.average, v); }},
      {"pd", [&](const py::handle& v) { set_optional(s.discard, v); }},
      {"dropout", [&](const py::handle& v) { set_optional(s.dropout, v); }},
      {"kappa_w", [&](const py::handle& v) { set_optional(s.kappa_w, v); }},
      {"kappa_r", [&](const py::handle& v) { set_optional(s.kappa_r, v); }},
      {"kappa_c", [&](const py::handle& v) { set_optional(s.kappa_c, v); }},
      {"kappa_m", [&](const py::handle& v) { set_optional(s.kappa_m, v); }},
      {"nlm_h", [&](const py::handle& v) { s.nlm.h = v.cast<float>(); }},
      {"noise_method", [&](const py::handle& v) { s.noise_method = v.cast<std::string>(); }},
      {"patch", [&](const py::handle& v) { s.patch = v.cast<int>(); }}};
  for (const auto& [key, value] : options) {
    const std::string name = py::str(key);
    const auto setter = setters.find(name);
    if (setter == setters.end()) throw Error(name, "", "unknown option of glint.denoise.run");
    set_option(name, value, setter->second);
  }
  // The CLI's choices (config is checked by the preset).
  if (s.device != "auto" && s.device != "cpu" && s.device != "cuda")
    throw Error("device", s.device, "must be auto, cpu or cuda");
  if (s.noise_method != "svd" && s.noise_method != "var" && s.noise_method != "variance")
    throw Error("noise_method", s.noise_method, "must be svd or var");
  return s;
}

py::array run(const py::object& image_arg, const std::string& method,
              const py::object& guidance_arg, const py::dict& options) {
  const auto& names = denoise::denoise_method_names();
  if (std::find(names.begin(), names.end(), method) == names.end())
    throw Error("method", method, "unknown method (nlm, dip, guided-dip, s2s, guided-s2s)");
  const denoise::DenoiserSettings settings = settings_from(options);
  const ImageF noisy = image_from_array(image_arg, "image");
  ImageF guidance;
  const bool guided = denoise::method_is_guided(method);
  if (guided && !guidance_arg.is_none()) {
    guidance = image_from_array(guidance_arg, "guidance");
    denoise::check_guidance(guidance, noisy, "guidance");
  }
  denoise::DenoiseRun result;
  {
    py::gil_scoped_release release;
    if (guided && guidance.empty()) guidance = denoise::estimate_guidance(noisy, settings);
    result = denoise::run_denoiser(method, settings, noisy, guided ? &guidance : nullptr);
  }
  return array_from_image(std::move(result.result));
}

}  // namespace

void bind_denoise(py::module_ m) {
  m.def("noise_map", &noise_map, py::arg("image"), py::arg("method") = "svd", py::arg("patch") = 7,
        py::arg("bins") = 256, py::arg("upper_quantile") = 0.95,
        R"(Per-pixel noise level and the guidance map made from it, as `glint denoise noise-map`.

Args:
    image: (H, W) or (H, W, C) float32/float64 (values as they are) or uint8/uint16
        (divided by 255 / 65535, as the file reader does); copied once into planes.
    method: 'svd' (a plane fitted to each half of the patch; edges and gradients do not look
        noisy) or 'var' (the plain patch variance).
    patch: patch side length, odd, >= 3.
    bins, upper_quantile: the remapping's histogram bins (8..65536) and the noise quantile
        that maps to 0 (0.5..1).

Returns:
    (guidance, noise, info): guidance (H, W) float32 in [0, 1] (1 = clean, keep; 0 = noisy);
    noise (H, W) float32, the raw level in squared image units; info: dict n_peak, lower,
    upper of the remapping (levels <= lower -> 1, >= upper -> 0). Both arrays own their data.

Raises:
    glint.Error: bad array, even or too small patch, non-finite values.)");
  m.def(
      "run",
      [](const py::object& image, const std::string& method, const py::object& guidance,
         const py::kwargs& options) { return run(image, method, guidance, options); },
      py::arg("image"), py::arg("method") = "guided-s2s", py::arg("guidance") = py::none(),
      R"(Denoise one image, as `glint denoise run`.

Args:
    image: (H, W) or (H, W, C) float32/float64/uint8/uint16 (as noise_map); any channel count.
    method: 'guided-s2s' (default), 's2s', 'guided-dip', 'dip' or 'nlm'.
    guidance: (H, W) guidance map (noise_map's first result) for the guided methods; None =
        estimated from the image (noise_method, patch).

Keyword options (the CLI's option names with '_' for '-'; None keeps the preset's value):
    config='fast' ('full' = the paper's settings, GPU-sized), device='auto' ('cpu',
    'cuda'), seed=1, iterations, predictions, levels, channels, lr, input_noise,
    average ('uniform'/'weighted'), pd, dropout, kappa_w, kappa_r, kappa_c, kappa_m,
    nlm_h=25, noise_method='svd', patch=7.

Returns:
    the denoised image, float32, (H, W, C) or (H, W) like the input.

The neural methods run in glint's libtorch plugin (denoise-nets.so, found next to the
installed library or through $GLINT_DENOISE_PLUGIN). The GIL is released while it runs.

Raises:
    glint.Error: unknown method or option, a guidance map of another size or with several
        channels, a missing plugin, a failed run.)");
}

}  // namespace glint::python
