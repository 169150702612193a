#pragma once
// The files of hapticsim view's browser page (web/view/ and three.js from npm), compiled into the
// binary by view_assets.S.in so the page works from the build tree, an installed package and a
// machine without the internet alike.
#include <span>
#include <string_view>

namespace hapticsim::view {

struct ViewAsset {
  std::string_view path;          ///< what the page asks for: "/", "/view.js", "/three.module.js"
  std::string_view content_type;  ///< the HTTP Content-Type it is served with
  std::string_view body;
};

/** Every file the page may load; anything else is 404. */
std::span<const ViewAsset> ViewAssets();

}  // namespace hapticsim::view
