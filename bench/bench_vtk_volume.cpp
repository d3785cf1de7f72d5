#include "bench/bench_vtk_volume.h"

#include <X11/Xlib.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkCommand.h>
#include <vtkFixedPointRayCastImage.h>
#include <vtkFixedPointVolumeRayCastMapper.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMultiThreader.h>
#include <vtkNew.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkPiecewiseFunction.h>
#include <vtkPointData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnsignedShortArray.h>
#include <vtkVolume.h>
#include <vtkVolumeProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>

#include "bench/bench_common.h"
#include "core/render/srgb.h"
#include "core/util/error.h"

namespace rtfact::bench {

using volume::BrickedVolume;
using volume::Storage;

namespace {

// The voxels in x-fastest order, as the stored type (VTK's fast paths are the integer ones).
template <class Array, class T>
vtkSmartPointer<vtkDataArray> voxelArray(const BrickedVolume& v) {
    auto arr = vtkSmartPointer<Array>::New();
    arr->SetNumberOfTuples(vtkIdType(v.voxelCount()));
    T* dst = arr->GetPointer(0);
    size_t n = 0;
    for (int k = 0; k < v.dims[2]; ++k)
        for (int j = 0; j < v.dims[1]; ++j)
            for (int i = 0; i < v.dims[0]; ++i) dst[n++] = T(v.stored(i, j, k));
    return arr;
}

std::string displayName() {
    const char* d = std::getenv("DISPLAY");
    return d ? d : "";
}

// Can this process talk to the X server in DISPLAY? (VTK aborts when it cannot.)
bool displayReachable() {
    Display* d = XOpenDisplay(nullptr);
    if (!d) return false;
    XCloseDisplay(d);
    return true;
}

void castEvent(vtkObject*, unsigned long event, void* clientData, void*) {
    auto* clock = static_cast<std::pair<Clock::time_point, double>*>(clientData);
    if (event == vtkCommand::VolumeMapperRenderStartEvent)
        clock->first = Clock::now();
    else
        clock->second = msSince(clock->first);
}

}  // namespace

struct VtkVolumePeer::Impl {
    int w = 0, h = 0;
    vtkNew<vtkImageData> data;
    vtkNew<vtkPiecewiseFunction> opacity;
    vtkNew<vtkColorTransferFunction> color;
    vtkNew<vtkVolumeProperty> property;
    vtkNew<vtkFixedPointVolumeRayCastMapper> mapper;
    vtkNew<vtkVolume> actor;
    vtkNew<vtkRenderer> renderer;
    vtkNew<vtkRenderWindow> window;
    vtkNew<vtkCallbackCommand> onCast;
    std::pair<Clock::time_point, double> cast;  // start of the cast, its length in ms
};

VtkVolumePeer::VtkVolumePeer(const VtkVolumeView& view) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    const BrickedVolume& v = *view.volume;
    m.w = view.width;
    m.h = view.height;
    if (!displayReachable())
        throw Error("VTK", std::string("cannot open the X display '") + displayName() +
                               "' (VTK's render window needs one; unset DISPLAY to get a virtual one)");

    // Stored values with the volume's spacing and origin: voxel (i,j,k) sits at
    // origin + (i,j,k) * spacing for both renderers.
    m.data->SetDimensions(v.dims[0], v.dims[1], v.dims[2]);
    m.data->SetSpacing(v.spacing.x, v.spacing.y, v.spacing.z);
    m.data->SetOrigin(v.origin.x, v.origin.y, v.origin.z);
    vtkSmartPointer<vtkDataArray> voxels;
    if (v.storage == Storage::U8)
        voxels = voxelArray<vtkUnsignedCharArray, unsigned char>(v);
    else if (v.storage == Storage::U16)
        voxels = voxelArray<vtkUnsignedShortArray, unsigned short>(v);
    else
        voxels = voxelArray<vtkFloatArray, float>(v);
    voxels->SetName("scalars");
    m.data->GetPointData()->SetScalars(voxels);

    // The TF over the window [lo, hi] in data units, moved to stored units
    // (data = stored * scale + offset); clamped outside like our table. Sampled densely
    // (our colours are interpolated in sRGB, then linearised) plus the exact opacity points.
    // plain names, not a structured binding: the lambdas below capture them (Clang < 16 cannot)
    const float lo = view.window.first, hi = view.window.second;
    auto storedOf = [&](float u) { return double((lo + u * (hi - lo) - v.offset) / v.scale); };
    auto tfX = [&](float u) { return view.tf.normalized ? u : lo + u * (hi - lo); };
    constexpr int kSamples = 1024;
    for (int i = 0; i < kSamples; ++i) {
        const float u = float(i) / float(kSamples - 1);
        const Vec3f c = view.tf.color(tfX(u));
        m.color->AddRGBPoint(storedOf(u), srgbToLinear(c.x), srgbToLinear(c.y), srgbToLinear(c.z));
        m.opacity->AddPoint(storedOf(u), std::clamp(view.tf.alpha(tfX(u)), 0.0f, 1.0f));
    }
    for (const auto& p : view.tf.opacity) {
        const float u = view.tf.normalized ? p.x : (p.x - lo) / (hi - lo);
        if (u >= 0.0f && u <= 1.0f) m.opacity->AddPoint(storedOf(u), std::clamp(p.a, 0.0f, 1.0f));
    }
    // MIP: VTK's pixel is colour(max) * opacity(max) with alpha opacity(max); ours is the TF
    // colour of the maximum, opaque. Opacity 1 over the whole range gives both the same picture.
    if (view.mip) {
        m.opacity->RemoveAllPoints();
        m.opacity->AddPoint(storedOf(0.0f), 1.0);
        m.opacity->AddPoint(storedOf(1.0f), 1.0);
    }
    m.property->SetColor(m.color);
    m.property->SetScalarOpacity(m.opacity);
    m.property->SetInterpolationTypeToLinear();
    // Opacity per voxel of distance, corrected for the step like ours: 1 - (1 - a)^step.
    const double voxel = double(std::min({v.spacing.x, v.spacing.y, v.spacing.z}));
    m.property->SetScalarOpacityUnitDistance(voxel);
    if (view.shaded) {
        // Our shaded mode: 0.2 + 0.8 |n.v| + 0.25 |n.v|^20 with a headlight.
        m.property->ShadeOn();
        m.property->SetAmbient(0.2);
        m.property->SetDiffuse(0.8);
        m.property->SetSpecular(0.25);
        m.property->SetSpecularPower(20.0);
    } else {
        m.property->ShadeOff();
    }

    // The same step in world units at every render, one ray per pixel.
    m.mapper->SetInputData(m.data);
    if (view.mip)
        m.mapper->SetBlendModeToMaximumIntensity();
    else
        m.mapper->SetBlendModeToComposite();
    m.mapper->AutoAdjustSampleDistancesOff();
    m.mapper->LockSampleDistanceToInputSpacingOff();
    m.mapper->SetSampleDistance(float(view.stepVoxels * voxel));
    m.mapper->SetInteractiveSampleDistance(float(view.stepVoxels * voxel));
    m.mapper->SetImageSampleDistance(1.0f);
    m.mapper->SetMinimumImageSampleDistance(1.0f);
    m.mapper->SetMaximumImageSampleDistance(1.0f);
    m.onCast->SetCallback(castEvent);
    m.onCast->SetClientData(&m.cast);
    m.mapper->AddObserver(vtkCommand::VolumeMapperRenderStartEvent, m.onCast);
    m.mapper->AddObserver(vtkCommand::VolumeMapperRenderEndEvent, m.onCast);
    m.actor->SetMapper(m.mapper);
    m.actor->SetProperty(m.property);

    // Our pinhole camera: vertical field of view, rays through pixel centres; VTK's
    // default headlight is the light of `shaded`.
    m.renderer->SetBackground(0.0, 0.0, 0.0);
    m.renderer->AddVolume(m.actor);
    vtkCamera* cam = m.renderer->GetActiveCamera();
    const CameraFrame& f = view.camera;
    cam->SetPosition(f.eye.x, f.eye.y, f.eye.z);
    cam->SetFocalPoint(f.at.x, f.at.y, f.at.z);
    cam->SetViewUp(f.up.x, f.up.y, f.up.z);
    cam->SetViewAngle(f.fovDeg);
    cam->OrthogonalizeViewUp();
    m.renderer->ResetCameraClippingRange();  // the caster clips rays at the near/far planes

    m.window->SetOffScreenRendering(1);
    m.window->SetMultiSamples(0);
    m.window->SetSize(m.w, m.h);
    m.window->AddRenderer(m.renderer);
    auto* gl = vtkOpenGLRenderWindow::SafeDownCast(m.window);
    if (!gl || !gl->SupportsOpenGL())
        throw Error("VTK", "no OpenGL context on display '" + displayName() + "' (Xvfb with Mesa's GLX is enough)");
}

VtkVolumePeer::~VtkVolumePeer() = default;

VtkVolumePeer::Timing VtkVolumePeer::render(int threads, int frames) {
    Impl& m = *impl_;
    vtkMultiThreader::SetGlobalMaximumNumberOfThreads(threads);
    m.mapper->SetNumberOfThreads(threads);
    m.window->Render();  // warm-up: tables, (gradients), GL resources
    Timing best{1e300, 1e300};
    for (int f = 0; f < std::max(frames, 1); ++f) {
        m.cast.second = 0;
        const auto t0 = Clock::now();
        m.window->Render();
        const double all = msSince(t0);
        if (m.cast.second < best.castMs) best = {m.cast.second, all};
    }
    return best;
}

std::vector<float> VtkVolumePeer::castImage() const {
    const Impl& m = *impl_;
    // RGBA in VTK's fixed point (32767 = 1), premultiplied, rows bottom-up, covering
    // the volume's screen rectangle from ImageOrigin.
    vtkFixedPointRayCastImage* ri = m.mapper->GetRayCastImage();
    int org[2], mem[2], use[2];
    ri->GetImageOrigin(org);
    ri->GetImageMemorySize(mem);
    ri->GetImageInUseSize(use);
    std::vector<float> out(size_t(m.w) * size_t(m.h) * 4, 0.0f);
    for (size_t p = 3; p < out.size(); p += 4) out[p] = 1.0f;
    for (int y = 0; y < use[1]; ++y)
        for (int x = 0; x < use[0]; ++x) {
            const int ox = x + org[0], oy = m.h - 1 - (y + org[1]);
            if (ox < 0 || ox >= m.w || oy < 0 || oy >= m.h) continue;
            const unsigned short* s = ri->GetImage() + (size_t(y) * size_t(mem[0]) + size_t(x)) * 4;
            float* d = &out[(size_t(oy) * size_t(m.w) + size_t(ox)) * 4];
            for (int c = 0; c < 3; ++c) d[c] = float(s[c]) / 32767.0f;
        }
    return out;
}

std::vector<float> VtkVolumePeer::image() {
    Impl& m = *impl_;
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(m.window);
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkImageData* img = grab->GetOutput();
    int dims[3];
    img->GetDimensions(dims);
    if (dims[0] != m.w || dims[1] != m.h) throw Error("VTK", "read back an image of the wrong size");
    const auto* px = static_cast<const unsigned char*>(img->GetScalarPointer());
    const int nc = img->GetNumberOfScalarComponents();
    // VTK's rows run bottom-up; its colours are our linear table's, premultiplied by the
    // ray's opacity and composited over the black background, as ours are.
    std::vector<float> out(size_t(m.w) * size_t(m.h) * 4);
    for (int y = 0; y < m.h; ++y)
        for (int x = 0; x < m.w; ++x) {
            const unsigned char* s = px + (size_t(m.h - 1 - y) * size_t(m.w) + size_t(x)) * size_t(nc);
            float* d = &out[(size_t(y) * size_t(m.w) + size_t(x)) * 4];
            for (int c = 0; c < 3; ++c) d[c] = float(s[c]) / 255.0f;
            d[3] = 1.0f;
        }
    return out;
}

namespace {

enum class XvfbStart { Ready, Missing, Failed, Timeout };

// Starts `Xvfb :display` and waits until it accepts connections (it writes its display
// number to -displayfd then). `pid` is the server's on Ready, -1 otherwise.
XvfbStart startXvfb(int display, int& pid) {
    pid = -1;
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) return XvfbStart::Failed;
    const pid_t child = fork();
    if (child < 0) {
        close(fds[0]);
        close(fds[1]);
        return XvfbStart::Failed;
    }
    if (child == 0) {
        prctl(PR_SET_PDEATHSIG, SIGTERM);  // never outlive the benchmark
        dup2(fds[1], 3);                   // dup2 clears close-on-exec on fd 3
        const int quiet = open("/dev/null", O_WRONLY);
        if (quiet >= 0) dup2(quiet, 2);
        const std::string name = ":" + std::to_string(display);
        execlp("Xvfb", "Xvfb", name.c_str(), "-displayfd", "3", "-nolisten", "tcp", "-noreset", "-screen", "0",
               "1280x1024x24", static_cast<char*>(nullptr));
        _exit(127);
    }
    close(fds[1]);
    std::string said;
    pollfd pfd{fds[0], POLLIN, 0};
    bool timedOut = false;
    while (said.find('\n') == std::string::npos) {
        if (poll(&pfd, 1, 30000) <= 0) {
            timedOut = true;
            break;
        }
        char buf[16];
        const ssize_t n = read(fds[0], buf, sizeof buf);
        if (n <= 0) break;  // the server exited
        said.append(buf, size_t(n));
    }
    close(fds[0]);
    if (said.find('\n') != std::string::npos) {
        pid = child;
        return XvfbStart::Ready;
    }
    int status = 0;
    kill(child, SIGTERM);
    waitpid(child, &status, 0);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127) return XvfbStart::Missing;
    return timedOut ? XvfbStart::Timeout : XvfbStart::Failed;
}

bool displayInUse(int display) {
    const std::string n = std::to_string(display);
    return access(("/tmp/.X" + n + "-lock").c_str(), F_OK) == 0 || access(("/tmp/.X11-unix/X" + n).c_str(), F_OK) == 0;
}

}  // namespace

VirtualDisplay::VirtualDisplay(int argc, char** argv) {
    const char* display = std::getenv("DISPLAY");
    if (display && *display) return;
    std::string cmd = "xvfb-run -a rtfact-bench";
    for (int i = 0; i < argc; ++i) cmd += std::string(" ") + argv[i];  // argv[0] is "volume"
    const std::string hint = "; run `" + cmd + "`, or pass --no-vtk";
    // -noreset: an X server resets when its last client leaves and refuses connections
    // meanwhile; our probe's connection closing right before VTK's made VTK abort now and
    // then (also under xvfb-run). Servers are started one at a time under an exclusive
    // lock, each on a display no lock or socket file claims, drawn at random far above
    // the usual ones, so concurrent benchmarks never race for a number.
    const int lock = open("/tmp/.rtfact-xvfb.lock", O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (lock >= 0) flock(lock, LOCK_EX);
    struct Unlock {
        int fd;
        ~Unlock() {
            if (fd >= 0) close(fd);  // releases the lock
        }
    } unlock{lock};
    std::mt19937 random(unsigned(getpid()) ^ unsigned(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::uniform_int_distribution<int> pick(1000, 29999);
    for (int attempt = 0; attempt < 20; ++attempt) {
        const int number = pick(random);
        if (displayInUse(number)) continue;
        switch (startXvfb(number, pid_)) {
            case XvfbStart::Ready: {
                setenv("DISPLAY", (":" + std::to_string(number)).c_str(), 1);
                std::fprintf(stderr,
                             "rtfact-bench: no DISPLAY: VTK's render window goes to a virtual X server (Xvfb :%d)\n",
                             number);
                return;
            }
            case XvfbStart::Missing:
                throw Error("VTK", "no DISPLAY and Xvfb is not installed (apt-get install xvfb)" + hint);
            case XvfbStart::Timeout:
                throw Error("VTK", "no DISPLAY and Xvfb did not start within 30 s" + hint);
            case XvfbStart::Failed:
                break;  // taken meanwhile by a server we do not know of: draw again
        }
    }
    throw Error("VTK", "no DISPLAY and Xvfb failed to start on 20 free-looking displays" + hint);
}

VirtualDisplay::~VirtualDisplay() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
    unsetenv("DISPLAY");
}

}  // namespace rtfact::bench
