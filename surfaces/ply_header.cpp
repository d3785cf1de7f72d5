#include "surfaces/ply_header.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/util/error.h"

namespace rtfact {

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

static int plyTypeBytes(const std::string& t) {
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
}

static char plyTypeKind(const std::string& t) {
    if (t == "float" || t == "double" || t == "float32" || t == "float64") return 'f';
    if (t[0] == 'u') return 'u';
    return 'i';
}

bool isPlyFile(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    char m[4] = {};
    in.read(m, 4);
    return in.gcount() == 4 && m[0] == 'p' && m[1] == 'l' && m[2] == 'y' && (m[3] == '\n' || m[3] == '\r');
}

PlyHeader readPlyHeader(const std::string& file) {
    std::error_code ec;
    PlyHeader h;
    h.fileBytes = std::filesystem::file_size(file, ec);
    if (ec) throw Error(file, "cannot read file size");
    std::ifstream in(file, std::ios::binary);
    if (!in) throw Error(file, "cannot open file");
    if (!isPlyFile(file)) throw Error(file, "not a PLY file (missing 'ply' magic)");
    // Lines are read byte by byte up to the limit: getline would take in a whole binary
    // file (or a giant comment) as one line before any check could run.
    std::streambuf* sb = in.rdbuf();
    uint64_t consumed = 0;
    std::string line;
    auto nextLine = [&]() {
        line.clear();
        for (int c; (c = sb->sbumpc()) != std::char_traits<char>::eof();) {
            if (++consumed > kMaxPlyHeaderBytes)
                throw Error(file, "PLY header longer than " + std::to_string(kMaxPlyHeaderBytes) +
                                      " bytes (the limit) before end_header");
            if (c == '\n') return true;
            line.push_back(char(c));
        }
        return !line.empty();
    };
    nextLine();  // "ply"
    bool haveFormat = false, ended = false;
    while (nextLine()) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        std::istringstream ls(line);
        std::string kw;
        ls >> kw;
        if (kw.empty() || kw == "comment" || kw == "obj_info") continue;
        if (kw == "end_header") {
            ended = true;
            break;
        }
        if (kw == "format") {
            std::string f, v;
            ls >> f >> v;
            if (f == "ascii")
                h.format = PlyHeader::Format::Ascii;
            else if (f == "binary_little_endian")
                h.format = PlyHeader::Format::BinaryLE;
            else if (f == "binary_big_endian")
                h.format = PlyHeader::Format::BinaryBE;
            else
                throw Error(file, "unknown PLY format '" + f + "'");
            haveFormat = true;
        } else if (kw == "element") {
            PlyElement e;
            std::string count;
            ls >> e.name >> count;
            if (e.name.empty() || count.empty() || count.find_first_not_of("0123456789") != std::string::npos ||
                count.size() > 12)
                throw Error(file, "bad PLY element line '" + line + "'");
            e.count = std::stoull(count);
            h.elements.push_back(e);
        } else if (kw == "property") {
            if (h.elements.empty()) throw Error(file, "PLY property before any element");
            PlyProperty p;
            std::string t;
            ls >> t;
            if (t == "list") {
                std::string ct, it;
                ls >> ct >> it >> p.name;
                p.isList = true;
                p.countBytes = plyTypeBytes(ct);
                p.typeBytes = plyTypeBytes(it);
                if (p.countBytes && p.typeBytes) {
                    p.countKind = plyTypeKind(ct);
                    p.typeKind = plyTypeKind(it);
                }
                if (!p.countBytes || !p.typeBytes) throw Error(file, "unknown PLY type in '" + line + "'");
            } else {
                p.typeBytes = plyTypeBytes(t);
                if (p.typeBytes) p.typeKind = plyTypeKind(t);
                ls >> p.name;
                if (!p.typeBytes) throw Error(file, "unknown PLY type '" + t + "'");
            }
            if (p.name.empty()) throw Error(file, "PLY property without a name");
            h.elements.back().props.push_back(p);
        } else {
            throw Error(file, "unexpected PLY header line '" + line + "'");
        }
    }
    if (!ended) throw Error(file, "PLY header not terminated by end_header");
    if (!haveFormat) throw Error(file, "PLY header has no format line");
    h.headerBytes = consumed;
    // The smallest data each element can occupy: binary sizes are exact for scalars and
    // a lower bound for lists (count only); ASCII needs at least one digit and one
    // separator per value.
    const uint64_t data = h.fileBytes > h.headerBytes ? h.fileBytes - h.headerBytes : 0;
    long double need = 0;
    for (const PlyElement& e : h.elements) {
        long double per = 0;
        for (const PlyProperty& p : e.props) {
            if (h.format == PlyHeader::Format::Ascii)
                per += 2;
            else
                per += p.isList ? p.countBytes : p.typeBytes;
        }
        need += per * (long double)e.count;
    }
    if (need > (long double)data) {
        std::ostringstream m;
        m << "truncated or lying PLY header: elements need at least " << (unsigned long long)need
          << " bytes but the file has " << data << " after the header";
        throw Error(file, m.str());
    }
    return h;
}

bool isPlyFaceElement(const std::string& element) { return element == "face" || element == "tristrips"; }

const PlyProperty* plyIndexList(const PlyElement& e) {
    for (const PlyProperty& p : e.props)
        if (p.isList && (p.name == "vertex_indices" || p.name == "vertex_index")) return &p;
    return nullptr;
}

bool plyHasFaces(const PlyHeader& h) {
    for (const PlyElement& e : h.elements)
        if (isPlyFaceElement(e.name) && e.count > 0 && plyIndexList(e)) return true;
    return false;
}

uint64_t plyTriangleEstimate(const PlyHeader& h) {
    const bool ascii = h.format == PlyHeader::Format::Ascii;
    uint64_t faces = 0, otherBytes = 0;
    int stripIndexBytes = 0;
    for (const PlyElement& e : h.elements) {
        const PlyProperty* idx = plyIndexList(e);
        if (e.name == "face") faces += e.count;
        // ASCII: most indices of n vertices have about as many digits as n - 1 (the
        // vertices' own bytes count as 2 per value, so the rest is generous anyway).
        if (e.name == "tristrips" && idx)
            stripIndexBytes =
                ascii ? 1 + std::max<int>(1, int(std::to_string(std::max<uint64_t>(h.count("vertex"), 1) - 1).size()))
                      : idx->typeBytes;
        // The same minimum sizes as the header check: counts only for lists.
        uint64_t per = 0;
        for (const PlyProperty& p : e.props) per += ascii ? 2 : p.isList ? p.countBytes : p.typeBytes;
        otherBytes += per * e.count;
    }
    const uint64_t data = h.fileBytes > h.headerBytes ? h.fileBytes - h.headerBytes : 0;
    const uint64_t strips = stripIndexBytes && data > otherBytes ? (data - otherBytes) / uint64_t(stripIndexBytes) : 0;
    return faces + strips;
}

}  // namespace rtfact
