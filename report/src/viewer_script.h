#pragma once
// The page's JavaScript: report/web/viewer.js with three.js, bundled by esbuild at build time and
// compiled in as text (report/CMakeLists.txt, cmake/embed_text.cmake).

#include <string_view>

namespace mneedle::report::detail {

std::string_view viewer_script();

}  // namespace mneedle::report::detail
