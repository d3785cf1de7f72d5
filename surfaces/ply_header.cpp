#include "surfaces/ply_header.h"

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
    std::string line;
    std::getline(in, line);
    bool haveFormat = false, ended = false;
    int lines = 0;
    while (std::getline(in, line)) {
        // A header is a few dozen short lines; anything else is a broken file.
        if (++lines > 10000 || line.size() > 4096) throw Error(file, "PLY header too long or not terminated");
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
            if (f == "ascii") h.format = PlyHeader::Format::Ascii;
            else if (f == "binary_little_endian") h.format = PlyHeader::Format::BinaryLE;
            else if (f == "binary_big_endian") h.format = PlyHeader::Format::BinaryBE;
            else throw Error(file, "unknown PLY format '" + f + "'");
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
    h.headerBytes = uint64_t(in.tellg());
    // The smallest data each element can occupy: binary sizes are exact for scalars and
    // a lower bound for lists (count only); ASCII needs at least one digit and one
    // separator per value.
    const uint64_t data = h.fileBytes > h.headerBytes ? h.fileBytes - h.headerBytes : 0;
    long double need = 0;
    for (const PlyElement& e : h.elements) {
        long double per = 0;
        for (const PlyProperty& p : e.props) {
            if (h.format == PlyHeader::Format::Ascii) per += 2;
            else per += p.isList ? p.countBytes : p.typeBytes;
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

}  // namespace rtfact
