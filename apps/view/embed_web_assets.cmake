# cmake -DOUT=file.cpp -DDIR=web -P embed_web_assets.cmake: writes the C++ table of the
# page's files (DIR/*.html *.js *.css) for web_assets.h (bytes as hex: any content is safe).
file(GLOB FILES ${DIR}/*.html ${DIR}/*.js ${DIR}/*.css)
list(SORT FILES)
set(entries "")
set(arrays "")
set(i 0)
foreach(f ${FILES})
  get_filename_component(name ${f} NAME)
  get_filename_component(ext ${f} LAST_EXT)
  if(ext STREQUAL ".html")
    set(type "text/html; charset=utf-8")
  elseif(ext STREQUAL ".js")
    set(type "text/javascript; charset=utf-8")
  elseif(ext STREQUAL ".css")
    set(type "text/css; charset=utf-8")
  else()
    set(type "application/octet-stream")
  endif()
  file(READ ${f} hex HEX)
  string(LENGTH "${hex}" n)
  math(EXPR bytes "${n} / 2")
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," hex "${hex}")
  string(APPEND arrays "const unsigned char a${i}[] = {${hex}0};\n")
  string(APPEND entries "    {\"/${name}\", \"${type}\", {reinterpret_cast<const char*>(a${i}), ${bytes}}},\n")
  math(EXPR i "${i} + 1")
endforeach()
file(WRITE ${OUT}.tmp "// Generated from apps/view/web by embed_web_assets.cmake: do not edit.
#include \"apps/view/web_assets.h\"

namespace rtfact::viewer {
namespace {
${arrays}const WebAsset assets[] = {
${entries}};
}  // namespace

const WebAsset* findWebAsset(std::string_view path) {
    if (path == \"/\") path = \"/index.html\";
    for (const WebAsset& a : assets)
        if (a.path == path) return &a;
    return nullptr;
}

}  // namespace rtfact::viewer
")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different ${OUT}.tmp ${OUT})
file(REMOVE ${OUT}.tmp)
