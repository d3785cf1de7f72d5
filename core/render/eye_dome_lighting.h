// Eye-dome lighting (Boucheny 2009; the shading CloudCompare, Potree and ParaView give
// unshaded point clouds): an image-space pass on the framebuffer's depth. Each pixel is
// darkened by how much nearer its neighbours are, in log depth, so that silhouettes and
// depth steps read as outlines and slopes as shade, whatever the points' colours.
#pragma once
#include <vector>

namespace rtfact {

// Darkens `rgba` (w x h RGBA floats) by the depth (w x h; infinite: background, left
// as it is). `strength` 1 is the usual look, 0 leaves the image unchanged; `radius`
// is the neighbour distance in pixels.
void applyEyeDomeLighting(std::vector<float>& rgba, const std::vector<float>& depth, int w, int h, float strength,
                          float radius = 1.5f);

}  // namespace rtfact
