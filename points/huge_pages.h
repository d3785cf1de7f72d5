// Forwarding header: the huge-page helpers live in core/util/huge_pages.h. resizeHuge
// keeps the old name for its remaining users (lod_kdtree_builder.cpp, point_prepare.cpp,
// bench/bench_points.cpp); include core/util/huge_pages.h in new code.
#pragma once
#include <vector>

#include "core/util/huge_pages.h"

namespace rtfact::points {

// Resizes a vector to n fresh elements, backed by huge pages where the kernel allows.
template <class T>
void resizeHuge(std::vector<T>& v, size_t n) {
    v.clear();
    v.shrink_to_fit();  // fresh memory: the advice only helps untouched pages
    resizeHugePages(v, n);
}

}  // namespace rtfact::points
