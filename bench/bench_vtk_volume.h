// The second peer of `rtfact-bench volume`: VTK's vtkFixedPointVolumeRayCastMapper, the
// CPU ray caster that ParaView and 3D Slicer users get without a GPU. It renders the same
// bricked volume (its stored values, as a vtkImageData), the same transfer function
// (sampled into a vtkPiecewiseFunction and a vtkColorTransferFunction over the same
// window, linear colours like our table), the same step (SampleDistance = step * spacing,
// opacity unit distance = one voxel, no automatic adjustment), camera, image size and
// thread count. VTK headers stay in the .cpp: they are slow to compile.
//
// VTK's render window needs an X server (Debian's VTK 9.1 has no EGL/OSMesa build):
// without DISPLAY, `VirtualDisplay` starts Xvfb for the run.
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/render/pinhole_camera.h"
#include "volume/brick_volume.h"
#include "volume/transfer_function.h"

namespace rtfact::bench {

struct VtkVolumeView {
    const volume::BrickedVolume* volume = nullptr;
    volume::TransferFunction tf;
    std::pair<float, float> window;  // data units, as our table's
    float stepVoxels = 1.0f;
    bool shaded = false;  // headlight Blinn-Phong like our `shaded` mode (not identical)
    bool mip = false;     // maximum intensity projection (its blend mode), opacity 1 like our `mip`
    CameraFrame camera;
    int width = 0, height = 0;
};

class VtkVolumePeer {
   public:
    // Builds the image data, transfer functions, mapper and an off-screen window.
    // Throws rtfact::Error("VTK", ...) when no OpenGL context can be made.
    explicit VtkVolumePeer(const VtkVolumeView& view);
    ~VtkVolumePeer();
    VtkVolumePeer(const VtkVolumePeer&) = delete;
    VtkVolumePeer& operator=(const VtkVolumePeer&) = delete;

    struct Timing {
        double castMs = 0;    // the mapper's ray casting (VolumeMapperRenderStart..End)
        double renderMs = 0;  // the whole vtkRenderWindow::Render() (setup, cast, texture draw)
    };
    // One warm-up frame, then the best of `frames`, on `threads` threads.
    Timing render(int threads, int frames);
    // The last frame read back (vtkWindowToImageFilter), top row first, linear RGB over
    // black as floats, alpha 1: w*h*4 like our frames.
    std::vector<float> image();
    // The mapper's own image of that frame before display (15-bit fixed point, no
    // texture draw, no 8-bit framebuffer): the ray caster's quality by itself.
    std::vector<float> castImage() const;

   private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// When DISPLAY is unset: starts a private Xvfb (the server picks a free display itself)
// and sets DISPLAY for this process until destroyed. Throws rtfact::Error naming the
// command to run by hand when Xvfb is missing or does not start. Does nothing when
// DISPLAY is set.
class VirtualDisplay {
   public:
    VirtualDisplay(int argc, char** argv);
    ~VirtualDisplay();
    VirtualDisplay(const VirtualDisplay&) = delete;
    VirtualDisplay& operator=(const VirtualDisplay&) = delete;

   private:
    int pid_ = -1;
};

}  // namespace rtfact::bench
