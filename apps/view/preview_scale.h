// PreviewScale: the frame-time controller of the viewer. While the camera moves, frames
// are rendered at 1/scale of the full resolution per axis, the scale chosen so that a
// frame takes about `targetMs`: the cost per pixel is learnt from the passes it is told
// about (frame times follow the pixel count closely for a fixed view and settings).
#pragma once

namespace rtfact::viewer {

class PreviewScale {
   public:
    PreviewScale(double targetMs = 40.0, int maxScale = 8) : targetMs_(targetMs), maxScale_(maxScale) {}
    // A pass of `pixels` pixels took `ms`.
    void observe(double ms, double pixels);
    // The scale for a full resolution of `fullPixels` pixels (1 .. maxScale).
    int scaleFor(double fullPixels) const;
    // Settings changed (cost unknown again: start from the coarsest preview).
    void reset() { msPerPixel_ = 0; }
    double targetMs() const { return targetMs_; }

   private:
    double targetMs_;
    int maxScale_;
    double msPerPixel_ = 0;  // smoothed; 0: nothing observed
};

}  // namespace rtfact::viewer
