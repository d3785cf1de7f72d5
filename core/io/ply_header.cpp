#include "core/io/ply_header.h"

#include <algorithm>
#include <fstream>

#include "core/io/mapped_file.h"
#include "core/util/error.h"

namespace rtfact::io {

size_t PlyElement::fixedBytes() const {
    size_t s = 0;
    for (const PlyProperty& p : props) {
        if (p.isList) return 0;
        s += size_t(scalarBytes(p.type));
    }
    return s;
}

const PlyElement* PlyHeader::find(const std::string& name) const {
    for (const PlyElement& e : elements)
        if (e.name == name) return &e;
    return nullptr;
}

bool PlyHeader::hasProperty(const std::string& element, const std::string& prop) const {
    const PlyElement* e = find(element);
    if (!e) return false;
    for (const PlyProperty& p : e->props)
        if (p.name == prop) return true;
    return false;
}

std::string PlyHeader::formatName() const {
    return format == PlyFormat::Ascii      ? "ply ascii"
           : format == PlyFormat::BinaryLE ? "ply binary_little_endian"
                                           : "ply binary_big_endian";
}

namespace {

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> w;
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const size_t s = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > s) w.push_back(line.substr(s, i - s));
    }
    return w;
}

// A header line in a message: short, and printable.
std::string shown(std::string_view line) {
    std::string s;
    for (const char c : line.substr(0, 80)) s += (c >= 0x20 && c < 0x7f) ? c : '?';
    return s;
}

ScalarType typeOf(const std::string& file, std::string_view t) {
    const auto ty = parsePlyScalarType(t);
    if (!ty) throw Error(file, "unknown PLY property type '" + shown(t) + "'");
    return *ty;
}

// At most 12 digits (a trillion entries): larger counts cannot fit in any file, and the
// bound keeps the size arithmetic below far from overflow.
uint64_t parseCount(const std::string& file, std::string_view count, const std::string& element) {
    if (count.empty() || count.size() > 12 || count.find_first_not_of("0123456789") != std::string_view::npos)
        throw Error(file, "bad count '" + shown(count) + "' for PLY element '" + element + "'");
    uint64_t n = 0;
    for (const char c : count) n = n * 10 + uint64_t(c - '0');
    return n;
}

// Element and property names end up in messages (and in `rtfact info`): one word of at
// most 255 bytes without control characters.
std::string nameOf(const std::string& file, std::string_view name, const char* what) {
    bool ok = !name.empty() && name.size() <= 255;
    for (const char c : name) ok = ok && (static_cast<unsigned char>(c) >= 0x20 && c != 0x7f);
    if (!ok) throw Error(file, std::string("bad PLY ") + what + " name '" + shown(name) + "'");
    return std::string(name);
}

Error tooLong(const std::string& file) {
    return Error(
        file, "PLY header longer than " + std::to_string(kMaxPlyHeaderBytes) + " bytes (the limit) before end_header");
}

std::string entries(const PlyElement& e) {
    return std::to_string(e.count) + (e.name == "vertex" ? " vertices" : e.name == "face" ? " faces" : " entries");
}

// The smallest body the elements can have: binary sizes are exact for scalars and a
// lower bound for lists (the length only); ASCII needs a digit and a separator per value
// (the last separator may be missing).
void checkSizes(const std::string& file, const PlyHeader& h) {
    const uint64_t data = h.fileBytes - h.headerBytes;
    uint64_t need = 0;
    for (const PlyElement& e : h.elements) {
        uint64_t per = 0;
        for (const PlyProperty& p : e.props)
            per += h.ascii() ? 2 : uint64_t(scalarBytes(p.isList ? p.countType : p.type));
        // No overflow: the per-entry sizes of all elements add up to less than 2^20 (8 bytes
        // for each of the property lines in 1 MiB) and every count is below 10^12 < 2^40.
        need += per * e.count;
        const uint64_t least = h.ascii() && need > 0 ? need - 1 : need;
        if (least > data)
            throw Error(file, "truncated or lying PLY header: element '" + e.name + "' declares " + entries(e) +
                                  "; the elements up to it need at least " + std::to_string(least) +
                                  " bytes but only " + std::to_string(data) + " bytes follow the header");
    }
}

}  // namespace

PlyHeader parsePlyHeader(std::string_view head, uint64_t fileBytes, const std::string& file) {
    if (head.size() > kMaxPlyHeaderBytes) head = head.substr(0, kMaxPlyHeaderBytes);
    if (head.size() < 4 || head.substr(0, 3) != "ply" || (head[3] != '\n' && head[3] != '\r'))
        throw Error(file, "not a PLY file (missing 'ply' magic)");
    PlyHeader h;
    h.fileBytes = fileBytes;
    bool haveFormat = false;
    size_t pos = head.find('\n');  // after "ply"
    while (true) {
        if (pos == std::string_view::npos || pos + 1 >= head.size()) {
            if (fileBytes > head.size() && head.size() >= kMaxPlyHeaderBytes) throw tooLong(file);
            throw Error(file, "PLY header not terminated by end_header (truncated?)");
        }
        const size_t start = pos + 1;
        pos = head.find('\n', start);
        // A line cut by the limit: whatever it says, the header is too long.
        if (pos == std::string_view::npos && fileBytes > head.size()) throw tooLong(file);
        std::string_view line = head.substr(start, pos == std::string_view::npos ? head.size() - start : pos - start);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        const std::vector<std::string_view> w = words(line);
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "end_header") {
            if (pos == std::string_view::npos) throw Error(file, "PLY header: end_header not followed by a newline");
            h.headerBytes = pos + 1;
            break;
        }
        if (w[0] == "format") {
            const std::string_view f = w.size() > 1 ? w[1] : std::string_view();
            if (f == "ascii")
                h.format = PlyFormat::Ascii;
            else if (f == "binary_little_endian")
                h.format = PlyFormat::BinaryLE;
            else if (f == "binary_big_endian")
                h.format = PlyFormat::BinaryBE;
            else
                throw Error(file, "unknown PLY format '" + shown(f) + "'");
            haveFormat = true;
        } else if (w[0] == "element") {
            if (w.size() != 3) throw Error(file, "bad PLY element line '" + shown(line) + "'");
            PlyElement e;
            e.name = nameOf(file, w[1], "element");
            e.count = parseCount(file, w[2], e.name);
            h.elements.push_back(std::move(e));
        } else if (w[0] == "property") {
            if (h.elements.empty()) throw Error(file, "PLY property before any element");
            PlyProperty p;
            if (w.size() > 1 && w[1] == "list") {
                if (w.size() < 4) throw Error(file, "bad PLY list property '" + shown(line) + "'");
                p.isList = true;
                p.countType = typeOf(file, w[2]);
                p.type = typeOf(file, w[3]);
                if (isFloatType(p.countType))
                    throw Error(file, "PLY list length type must be an integer in '" + shown(line) + "'");
                if (w.size() > 4) p.name = nameOf(file, w[4], "property");
            } else {
                if (w.size() < 2) throw Error(file, "bad PLY property line '" + shown(line) + "'");
                p.type = typeOf(file, w[1]);
                if (w.size() > 2) p.name = nameOf(file, w[2], "property");
            }
            if (p.name.empty()) throw Error(file, "PLY property without a name");
            h.elements.back().props.push_back(std::move(p));
        } else {
            throw Error(file, "unexpected PLY header line '" + shown(line) + "'");
        }
    }
    if (!haveFormat) throw Error(file, "PLY header has no format line");
    for (const PlyElement& e : h.elements)
        if (e.count > 0 && e.props.empty())
            throw Error(file, "PLY element '" + e.name + "' declares " + entries(e) + " but no properties");
    checkSizes(file, h);
    return h;
}

PlyHeader readPlyHeader(const MappedFile& f) {
    return parsePlyHeader(f.bytes().substr(0, kMaxPlyHeaderBytes), f.size(), f.name());
}

bool isPlyFile(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    char m[4] = {};
    in.read(m, 4);
    return in.gcount() == 4 && m[0] == 'p' && m[1] == 'l' && m[2] == 'y' && (m[3] == '\n' || m[3] == '\r');
}

}  // namespace rtfact::io
