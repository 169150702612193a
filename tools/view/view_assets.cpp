#include "tools/view/view_assets.hpp"

#include <array>

// Begin and end of each file, from the .incbin directives of the generated view_assets.S.
#define HAPTICSIM_VIEW_ASSET(name) \
  extern "C" const char hapticsim_view_##name##_begin[], hapticsim_view_##name##_end[];
HAPTICSIM_VIEW_ASSET(index_html)
HAPTICSIM_VIEW_ASSET(view_js)
HAPTICSIM_VIEW_ASSET(three_module_js)
HAPTICSIM_VIEW_ASSET(three_core_js)
HAPTICSIM_VIEW_ASSET(orbit_controls_js)
#undef HAPTICSIM_VIEW_ASSET

namespace hapticsim::view {
namespace {

std::string_view Body(const char* begin, const char* end) {
  return {begin, static_cast<std::string_view::size_type>(end - begin)};
}

constexpr std::string_view kHtml = "text/html; charset=utf-8";
constexpr std::string_view kJs = "text/javascript; charset=utf-8";

}  // namespace

std::span<const ViewAsset> ViewAssets() {
  static const std::array<ViewAsset, 5> assets{{
      {"/", kHtml, Body(hapticsim_view_index_html_begin, hapticsim_view_index_html_end)},
      {"/view.js", kJs, Body(hapticsim_view_view_js_begin, hapticsim_view_view_js_end)},
      {"/three.module.js", kJs,
       Body(hapticsim_view_three_module_js_begin, hapticsim_view_three_module_js_end)},
      {"/three.core.js", kJs,
       Body(hapticsim_view_three_core_js_begin, hapticsim_view_three_core_js_end)},
      {"/OrbitControls.js", kJs,
       Body(hapticsim_view_orbit_controls_js_begin, hapticsim_view_orbit_controls_js_end)},
  }};
  return assets;
}

}  // namespace hapticsim::view
