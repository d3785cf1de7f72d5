// Turning VTK's console chatter into one-line rtfact errors. Header-only and included
// only by loaders that link VTK (surfaces/, volume/); the core itself does not use VTK.
#pragma once
#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObject.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>

#include <string>

namespace rtfact {

// The last line of a VTK message (they are multi-line, with source locations).
inline std::string vtkLastLine(std::string m) {
    while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
    const size_t nl = m.rfind('\n');
    if (nl != std::string::npos) m = m.substr(nl + 1);
    // Drop the "vtkSomeReader (0x55d0c0ffee00): " prefix: the object address means nothing to a user.
    const size_t addr = m.find(" (0x");
    const size_t close = m.find("): ", addr == std::string::npos ? 0 : addr);
    if (addr != std::string::npos && close != std::string::npos && m.find(' ') == addr) m = m.substr(close + 3);
    return m;
}

// Collects the error and warning events of a reader so they become one Error instead
// of text on stderr.
struct VtkErrors {
    std::string first;
    vtkNew<vtkCallbackCommand> callback;
    VtkErrors() {
        callback->SetCallback(&VtkErrors::onEvent);
        callback->SetClientData(this);
    }
    void observe(vtkObject* o, bool warnings = true) {
        o->AddObserver(vtkCommand::ErrorEvent, callback);
        if (warnings) o->AddObserver(vtkCommand::WarningEvent, callback);
    }
    static void onEvent(vtkObject*, unsigned long, void* client, void* data) {
        auto* self = static_cast<VtkErrors*>(client);
        if (self->first.empty() && data) self->first = vtkLastLine(static_cast<const char*>(data));
        if (self->first.empty()) self->first = "reader error";
    }
};

// While a file loads, VTK's global output window and logger are swallowed: helpers (XML
// parser, DICOM parser, ...) print through them rather than through reader events.
struct QuietVtkOutput {
    vtkSmartPointer<vtkOutputWindow> previous;
    vtkNew<vtkStringOutputWindow> text;
    vtkLogger::Verbosity verbosity;
    QuietVtkOutput() {
        previous = vtkOutputWindow::GetInstance();
        vtkOutputWindow::SetInstance(text);
        verbosity = vtkLogger::GetCurrentVerbosityCutoff();
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
    ~QuietVtkOutput() {
        vtkOutputWindow::SetInstance(previous);
        vtkLogger::SetStderrVerbosity(verbosity);
    }
    QuietVtkOutput(const QuietVtkOutput&) = delete;
    QuietVtkOutput& operator=(const QuietVtkOutput&) = delete;
    // The last line of the first message VTK emitted ("" when none).
    std::string firstMessage() const {
        std::string m = text->GetOutput();
        const size_t end = m.find("\n\n");
        if (end != std::string::npos) m = m.substr(0, end);
        return vtkLastLine(m);
    }
};

}  // namespace rtfact
