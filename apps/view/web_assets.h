// The page's files (apps/view/web), built into the binary at build time
// (embed_web_assets.cmake): the server serves these and nothing else.
#pragma once
#include <string_view>

namespace rtfact::viewer {

struct WebAsset {
    std::string_view path;  // "/index.html", "/viewer.js" ...
    std::string_view contentType;
    std::string_view body;
};

// nullptr for any other path.
const WebAsset* findWebAsset(std::string_view path);

}  // namespace rtfact::viewer
