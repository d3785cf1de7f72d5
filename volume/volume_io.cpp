// Own parsers for the simple volume formats (raw, MetaImage, NRRD, NIfTI): small, and
// they validate every size against the file before allocating, which VTK's readers do not.
#include "volume/volume_io.h"

#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>

#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/memory_budget.h"
#include "core/util/progress.h"

namespace fs = std::filesystem;

namespace rtfact::volume {

namespace {

enum class Src { U8, I8, U16, I16, U32, I32, F32, F64 };
int srcBytes(Src s) {
    switch (s) {
        case Src::U8:
        case Src::I8:
            return 1;
        case Src::U16:
        case Src::I16:
            return 2;
        case Src::U32:
        case Src::I32:
        case Src::F32:
            return 4;
        default:
            return 8;
    }
}
const char* srcName(Src s) {
    static const char* n[] = {"u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"};
    return n[int(s)];
}

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower((unsigned char)c));
    return s;
}
std::string trim(const std::string& s) {
    size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
    return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
}
bool endsWith(const std::string& s, const std::string& suf) {
    return s.size() >= suf.size() && s.compare(s.size() - suf.size(), suf.size(), suf) == 0;
}

uint64_t fileSize(const std::string& path) {
    requireRegularFile(path);
    std::error_code ec;
    const auto s = fs::file_size(path, ec);
    if (ec) throw Error(path, "cannot open file (" + ec.message() + ")");
    return s;
}

// Sequential bytes from a file at an offset, raw or zlib/gzip compressed. A compressed
// stream is only complete once zlib has seen its end and checked its trailer (CRC-32 and
// length for gzip, Adler-32 for zlib): finish() decodes up to there, so a stream cut after
// the bytes a header asks for is an error rather than a silent success.
class ByteStream {
   public:
    ByteStream(const std::string& path, uint64_t offset, bool compressed) : path_(path), compressed_(compressed) {
        requireRegularFile(path);  // a FIFO would block fopen
        f_ = std::fopen(path.c_str(), "rb");
        if (!f_) throw Error(path, "cannot open file");
        if (fseeko(f_, off_t(offset), SEEK_SET) != 0) throw Error(path, "cannot seek to the data");
        if (compressed_) {
            std::memset(&z_, 0, sizeof(z_));
            if (inflateInit2(&z_, 15 + 32) != Z_OK) throw Error(path, "cannot initialise zlib");
            zinit_ = true;
        }
    }
    ~ByteStream() {
        if (zinit_) inflateEnd(&z_);
        if (f_) std::fclose(f_);
    }
    ByteStream(const ByteStream&) = delete;
    ByteStream& operator=(const ByteStream&) = delete;

    // Reads exactly n bytes or throws naming what was being read.
    void read(void* dst, size_t n, const char* what) {
        const size_t got = readSome(static_cast<uint8_t*>(dst), n);
        if (got != n)
            throw Error(path_, std::string("truncated ") + (compressed_ ? "compressed " : "") + what + ": needed " +
                                   std::to_string(n) + " bytes, got " + std::to_string(got));
    }
    void skip(uint64_t n, const char* what) {
        std::vector<uint8_t> tmp(std::min<uint64_t>(n, 1 << 16));
        while (n > 0) {
            const size_t k = size_t(std::min<uint64_t>(n, tmp.size()));
            read(tmp.data(), k, what);
            n -= k;
        }
    }
    // Compressed: decodes (and drops) the rest of the stream, checking every member's
    // trailer; throws when the file ends inside a member.
    void finish() {
        if (!compressed_) return;
        std::vector<uint8_t> tmp(1 << 16);
        while (readSome(tmp.data(), tmp.size()) == tmp.size()) {
        }
    }

   private:
    size_t readSome(uint8_t* dst, size_t n) {
        if (!compressed_) return std::fread(dst, 1, n, f_);
        z_.next_out = dst;
        z_.avail_out = uInt(n);
        while (z_.avail_out > 0 && !ended_) step();
        return n - z_.avail_out;
    }
    // One inflate call (or the input it needs). Ends cleanly only at the end of the file
    // after a complete member (optionally followed by zero padding, as gzip -d accepts).
    void step() {
        if (z_.avail_in == 0) {
            const size_t k = std::fread(in_, 1, sizeof(in_), f_);
            if (k == 0) {
                if (std::ferror(f_)) throw Error(path_, "read error in compressed data");
                if (inMember_)
                    throw Error(path_, "truncated compressed data: the file ends before the end of the " + format() +
                                           " stream and its " + trailer() + " trailer");
                ended_ = true;
                return;
            }
            z_.next_in = in_;
            z_.avail_in = uInt(k);
        }
        if (!inMember_ && members_ > 0) {
            // after a complete member: zero padding to the end of the file, or another member
            while (z_.avail_in > 0 && *z_.next_in == 0) {
                ++z_.next_in;
                --z_.avail_in;
                padding_ = true;
            }
            if (z_.avail_in == 0) return;
            if (padding_) throw Error(path_, "unexpected bytes after the end of the compressed data");
            if (inflateReset(&z_) != Z_OK) throw Error(path_, "cannot reset zlib");
        }
        if (!inMember_) gzip_ = z_.avail_in >= 2 && z_.next_in[0] == 0x1f && z_.next_in[1] == 0x8b;
        inMember_ = true;
        const uInt before = z_.avail_in;
        const int r = inflate(&z_, Z_NO_FLUSH);
        if (r == Z_STREAM_END) {
            inMember_ = false;
            ++members_;
            return;
        }
        if (r == Z_OK || (r == Z_BUF_ERROR && (z_.avail_in == 0 || z_.avail_in != before))) return;
        const std::string msg = z_.msg ? z_.msg : "error " + std::to_string(r);
        if (msg == "incorrect data check" || msg == "incorrect length check")
            throw Error(path_, "corrupt compressed data: " + trailer() +
                                   " trailer does not match the data (zlib: " + msg + ")");
        throw Error(path_, "corrupt compressed data (zlib: " + msg + ")");
    }
    std::string format() const { return gzip_ ? "gzip" : "zlib"; }
    std::string trailer() const { return gzip_ ? "CRC-32/length" : "Adler-32"; }

    std::string path_;
    bool compressed_;
    FILE* f_ = nullptr;
    z_stream z_{};
    bool zinit_ = false;
    bool inMember_ = false, ended_ = false, padding_ = false, gzip_ = true;
    int members_ = 0;
    uint8_t in_[1 << 16];
};

// One piece of the voxel payload: `bytes` decoded bytes from `path`.
struct Piece {
    std::string path;
    uint64_t offset = 0;  // in the file (before decompression)
    uint64_t skip = 0;    // decoded bytes to drop first
    bool compressed = false;
    uint64_t bytes = 0;
    bool skipFromEnd = false;  // NRRD "byte skip: -1": data are the last bytes of the file
};

// Before allocating: can the pieces' files hold what the header claims?
void checkPieces(const std::string& header, std::vector<Piece>& pieces) {
    for (Piece& p : pieces) {
        const uint64_t fsz = fileSize(p.path);
        if (p.skipFromEnd && !p.compressed) {
            if (fsz < p.bytes)
                throw Error(p.path, "data file holds " + std::to_string(fsz) + " bytes, header needs " +
                                        std::to_string(p.bytes));
            p.offset = fsz - p.bytes;
            p.skip = 0;
        }
        if (p.offset > fsz)
            throw Error(p.path, "data offset " + std::to_string(p.offset) + " is beyond the end of the file (" +
                                    std::to_string(fsz) + " bytes)");
        const uint64_t avail = fsz - p.offset;
        if (!p.compressed) {
            if (avail < p.skip + p.bytes)
                throw Error(p.path, "size mismatch: header " +
                                        (header == p.path ? std::string() : "(" + header + ") ") + "needs " +
                                        std::to_string(p.skip + p.bytes) + " bytes of data, file has " +
                                        std::to_string(avail));
        } else {
            // deflate cannot compress better than about 1032:1
            const double maxOut = double(avail) * 1032.0 + 65536.0;
            if (double(p.skip + p.bytes) > maxOut)
                throw Error(p.path, "header claims " + std::to_string(p.skip + p.bytes) + " decompressed bytes, but " +
                                        std::to_string(avail) + " compressed bytes cannot hold that many");
        }
    }
}

Storage storageFor(Src s) {
    switch (s) {
        case Src::U8:
        case Src::I8:
            return Storage::U8;
        case Src::U16:
        case Src::I16:
            return Storage::U16;
        default:
            return Storage::F32;
    }
}

template <class T>
T loadLE(const uint8_t* p, bool swap) {
    uint8_t b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (swap) std::reverse(b, b + sizeof(T));
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
}

// Reads the pieces and converts the source type into the grid's compact storage.
void decodePayload(VolumeGrid& g, Src src, bool bigEndian, std::vector<Piece>& pieces, const std::string& header,
                   bool progress) {
    const uint64_t n = g.voxelCount();
    const int sb = srcBytes(src);
    uint64_t total = 0;
    for (const Piece& p : pieces) total += p.bytes;
    if (total != n * uint64_t(sb))
        throw Error(header, "data pieces hold " + std::to_string(total) + " bytes, expected " +
                                std::to_string(n * uint64_t(sb)));
    checkPieces(header, pieces);
    g.sourceType = srcName(src);
    // The dense grid plus its bricked copy for rendering.
    checkMemory(header, n * uint64_t(storageBytes(storageFor(src))) * 2, "the volume",
                "a sparse OpenVDB grid renders without densifying");
    g.allocate(storageFor(src));
    const bool swap = bigEndian && sb > 1;
    std::vector<uint8_t> buf(size_t(1) << 20);
    uint64_t voxel = 0;
    Progress prog("load", total, progress);
    for (const Piece& p : pieces) {
        ByteStream s(p.path, p.offset, p.compressed);
        if (p.skip) s.skip(p.skip, "header bytes");
        uint64_t left = p.bytes;
        while (left > 0) {
            const size_t k = size_t(std::min<uint64_t>(left, buf.size()));
            s.read(buf.data(), k, "voxel data");
            const size_t cnt = k / size_t(sb);
            const uint8_t* b = buf.data();
            switch (src) {
                case Src::U8:
                    std::memcpy(g.bytes.data() + voxel, b, cnt);
                    break;
                case Src::I8:
                    for (size_t i = 0; i < cnt; ++i) g.bytes[voxel + i] = uint8_t(b[i] ^ 0x80);
                    break;
                case Src::U16: {
                    uint16_t* d = g.data<uint16_t>() + voxel;
                    for (size_t i = 0; i < cnt; ++i) d[i] = loadLE<uint16_t>(b + 2 * i, swap);
                    break;
                }
                case Src::I16: {
                    uint16_t* d = g.data<uint16_t>() + voxel;
                    for (size_t i = 0; i < cnt; ++i) d[i] = uint16_t(loadLE<uint16_t>(b + 2 * i, swap) ^ 0x8000u);
                    break;
                }
                default: {
                    float* d = g.data<float>() + voxel;
                    for (size_t i = 0; i < cnt; ++i) {
                        const uint8_t* q = b + size_t(sb) * i;
                        float v;
                        if (src == Src::U32)
                            v = float(loadLE<uint32_t>(q, swap));
                        else if (src == Src::I32)
                            v = float(loadLE<int32_t>(q, swap));
                        else if (src == Src::F32)
                            v = loadLE<float>(q, swap);
                        else
                            v = float(loadLE<double>(q, swap));
                        d[i] = std::isfinite(v) ? v : 0.0f;  // NaN/inf voxels read as 0
                    }
                }
            }
            voxel += cnt;
            left -= k;
            prog.add(k);
        }
        s.finish();
    }
    prog.finish();
    // Signed types live shifted in unsigned storage.
    if (src == Src::I8) g.offset += -128.0f * g.scale;
    if (src == Src::I16) g.offset += -32768.0f * g.scale;
}

Src parseSrcType(const std::string& file, std::string t) {
    t = lower(trim(t));
    static const std::map<std::string, Src> m = {{"u8", Src::U8},
                                                 {"uint8", Src::U8},
                                                 {"uchar", Src::U8},
                                                 {"unsigned char", Src::U8},
                                                 {"uint8_t", Src::U8},
                                                 {"met_uchar", Src::U8},
                                                 {"i8", Src::I8},
                                                 {"int8", Src::I8},
                                                 {"signed char", Src::I8},
                                                 {"int8_t", Src::I8},
                                                 {"met_char", Src::I8},
                                                 {"char", Src::I8},
                                                 {"u16", Src::U16},
                                                 {"uint16", Src::U16},
                                                 {"ushort", Src::U16},
                                                 {"unsigned short", Src::U16},
                                                 {"unsigned short int", Src::U16},
                                                 {"uint16_t", Src::U16},
                                                 {"met_ushort", Src::U16},
                                                 {"i16", Src::I16},
                                                 {"int16", Src::I16},
                                                 {"short", Src::I16},
                                                 {"short int", Src::I16},
                                                 {"signed short", Src::I16},
                                                 {"signed short int", Src::I16},
                                                 {"int16_t", Src::I16},
                                                 {"met_short", Src::I16},
                                                 {"u32", Src::U32},
                                                 {"uint", Src::U32},
                                                 {"unsigned int", Src::U32},
                                                 {"uint32", Src::U32},
                                                 {"uint32_t", Src::U32},
                                                 {"met_uint", Src::U32},
                                                 {"i32", Src::I32},
                                                 {"int", Src::I32},
                                                 {"signed int", Src::I32},
                                                 {"int32", Src::I32},
                                                 {"int32_t", Src::I32},
                                                 {"met_int", Src::I32},
                                                 {"f32", Src::F32},
                                                 {"float", Src::F32},
                                                 {"float32", Src::F32},
                                                 {"met_float", Src::F32},
                                                 {"f64", Src::F64},
                                                 {"double", Src::F64},
                                                 {"float64", Src::F64},
                                                 {"met_double", Src::F64}};
    auto it = m.find(t);
    if (it == m.end()) throw Error(file, "unsupported voxel type '" + t + "'");
    return it->second;
}

std::vector<std::string> splitWords(const std::string& s) {
    std::istringstream is(s);
    std::vector<std::string> w;
    std::string x;
    while (is >> x) w.push_back(x);
    return w;
}
double parseNumber(const std::string& file, const std::string& s, const std::string& what) {
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (s.empty() || end == s.c_str() || *end != '\0' || !std::isfinite(v))
        throw Error(file, "bad " + what + " '" + s + "'");
    return v;
}

void setDims(VolumeGrid& g, const std::string& file, const std::vector<int64_t>& d) {
    if (d.size() != 3) throw Error(file, "expected 3 dimensions, got " + std::to_string(d.size()));
    int64_t dd[3] = {d[0], d[1], d[2]};
    checkedVoxelCount(file, dd);
    for (int a = 0; a < 3; ++a) g.dims[a] = int(dd[a]);
}
void setSpacing(VolumeGrid& g, const std::string& file, const std::vector<double>& s) {
    for (int a = 0; a < 3 && a < int(s.size()); ++a) {
        if (!(s[a] > 0) || !std::isfinite(s[a])) throw Error(file, "spacing must be positive and finite");
        g.spacing[a] = float(s[a]);
    }
}

// Reads a text header up to (not including) the first blank line or `limit` bytes.
std::string readTextHead(const std::string& path, size_t limit) {
    requireRegularFile(path);
    std::ifstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot open file");
    std::string s(limit, '\0');
    f.read(s.data(), std::streamsize(limit));
    s.resize(size_t(f.gcount()));
    return s;
}

// A modality value as DICOM spells it: "MET_MOD_CT" (MetaImage), "ct", "MR" -> "CT", "MR".
std::string modalityTerm(std::string v) {
    v = trim(v);
    for (char& c : v) c = char(std::toupper((unsigned char)c));
    if (v.rfind("MET_MOD_", 0) == 0) v = v.substr(8);
    if (v == "MRI") v = "MR";
    if (v == "PET") v = "PT";
    if (v.empty() || v == "OTHER" || v == "UNKNOWN" || v.size() > 16) return "";
    for (char c : v)
        if (!std::isalnum((unsigned char)c)) return "";
    return v;
}
// "CT" or "MR" when free text names the modality as a word ("CT scan of a bonsai tree").
std::string modalityWord(const std::string& text) {
    std::string word;
    for (size_t i = 0; i <= text.size(); ++i) {
        const char c = i < text.size() ? text[i] : ' ';
        if (std::isalnum((unsigned char)c)) {
            word.push_back(c);
            continue;
        }
        if (word == "CT" || word == "MR" || word == "MRI") return word == "CT" ? "CT" : "MR";
        word.clear();
    }
    return "";
}
// Free text from a fixed-size, NUL-padded header field.
std::string headerText(const uint8_t* p, size_t n) {
    std::string s(reinterpret_cast<const char*>(p), n);
    return s.substr(0, s.find('\0'));
}

// ---- raw -------------------------------------------------------------------------

VolumeGrid loadRaw(const std::string& path, const VolumeLoadOptions& o) {
    if (!o.dims) throw Error(path, "raw volume needs --dims X,Y,Z and --type u8|u16|i16|f32");
    if (o.type.empty()) throw Error(path, "raw volume needs --type u8|u16|i16|f32");
    VolumeGrid g;
    setDims(g, path, {(*o.dims)[0], (*o.dims)[1], (*o.dims)[2]});
    const Src src = parseSrcType(path, o.type);
    const uint64_t need = g.voxelCount() * uint64_t(srcBytes(src));
    const uint64_t fsz = fileSize(path);
    if (fsz != o.headerSkip + need)
        throw Error(path,
                    "raw size mismatch: dims and type need " + std::to_string(need) + " bytes" +
                        (o.headerSkip ? " after a " + std::to_string(o.headerSkip) + "-byte header" : std::string()) +
                        ", file has " + std::to_string(fsz));
    std::vector<Piece> pieces{{path, o.headerSkip, 0, false, need}};
    decodePayload(g, src, lower(o.endian) == "big", pieces, path, o.progress);
    return g;
}

// ---- MetaImage -------------------------------------------------------------------

VolumeGrid loadMetaImage(const std::string& path, const VolumeLoadOptions& o) {
    const uint64_t fsz = fileSize(path);
    const std::string head = readTextHead(path, size_t(std::min<uint64_t>(fsz, 1 << 16)));
    std::map<std::string, std::string> kv;
    size_t pos = 0, dataStart = 0;
    bool haveData = false;
    while (pos < head.size()) {
        size_t e = head.find('\n', pos);
        if (e == std::string::npos) {
            if (head.size() == fsz)
                e = head.size();
            else
                throw Error(path, "MetaImage header line too long or header not terminated");
        }
        const std::string line = head.substr(pos, e - pos);
        pos = e + 1;
        const size_t eq = line.find('=');
        if (trim(line).empty()) continue;
        if (eq == std::string::npos) throw Error(path, "bad MetaImage header line '" + trim(line).substr(0, 60) + "'");
        const std::string key = lower(trim(line.substr(0, eq)));
        kv[key] = trim(line.substr(eq + 1));
        if (key == "elementdatafile") {
            dataStart = std::min(pos, head.size());
            haveData = true;
            break;
        }
    }
    if (!haveData) throw Error(path, "MetaImage header has no ElementDataFile");
    auto get = [&](const char* k) -> std::string {
        auto it = kv.find(k);
        return it == kv.end() ? std::string() : it->second;
    };
    const std::string ndims = get("ndims");
    if (!ndims.empty() && ndims != "3")
        throw Error(path, "MetaImage NDims = " + ndims + ": only 3D volumes are supported");
    const auto ds = splitWords(get("dimsize"));
    if (ds.size() != 3) throw Error(path, "MetaImage DimSize must have 3 values");
    std::vector<int64_t> d;
    for (auto& w : ds) {
        const double v = parseNumber(path, w, "DimSize");
        if (v != std::floor(v) || v < -1e15 || v > 1e15) throw Error(path, "bad DimSize '" + w + "'");
        d.push_back(int64_t(v));
    }
    VolumeGrid g;
    setDims(g, path, d);
    std::string sp = get("elementspacing");
    if (sp.empty()) sp = get("elementsize");
    if (!sp.empty()) {
        std::vector<double> s;
        for (auto& w : splitWords(sp)) s.push_back(parseNumber(path, w, "ElementSpacing"));
        setSpacing(g, path, s);
    }
    std::string org = get("offset");
    if (org.empty()) org = get("position");
    if (!org.empty()) {
        auto w = splitWords(org);
        for (int a = 0; a < 3 && a < int(w.size()); ++a) g.origin[a] = float(parseNumber(path, w[a], "Offset"));
    }
    const std::string ch = get("elementnumberofchannels");
    if (!ch.empty() && ch != "1")
        throw Error(path, "MetaImage with " + ch + " channels: only scalar volumes are supported");
    if (get("elementtype").empty()) throw Error(path, "MetaImage header has no ElementType");
    const Src src = parseSrcType(path, get("elementtype"));
    std::string msb = lower(get("elementbyteordermsb"));
    if (msb.empty()) msb = lower(get("binarydatabyteordermsb"));
    const bool big = msb == "true" || msb == "1";
    const bool compressed = lower(get("compresseddata")) == "true";
    if (const std::string m = modalityTerm(get("modality")); !m.empty()) g.meta = {m, "MetaImage Modality"};
    const std::string df = get("elementdatafile");
    const uint64_t bytes = g.voxelCount() * uint64_t(srcBytes(src));
    std::vector<Piece> pieces;
    const std::string hs = get("headersize");
    int64_t headerSize = 0;
    if (!hs.empty()) headerSize = int64_t(parseNumber(path, hs, "HeaderSize"));
    if (lower(df) == "local") {
        pieces.push_back({path, dataStart, 0, compressed, bytes});
    } else {
        if (df.find("%") != std::string::npos || lower(df) == "list")
            throw Error(path, "MetaImage slice lists are not supported");
        const std::string dp = (fs::path(path).parent_path() / df).string();
        Piece p{dp, 0, 0, compressed, bytes};
        if (headerSize > 0) p.offset = uint64_t(headerSize);
        if (headerSize == -1) p.skipFromEnd = true;
        pieces.push_back(p);
    }
    decodePayload(g, src, big, pieces, path, o.progress);
    return g;
}

// ---- NRRD ------------------------------------------------------------------------

VolumeGrid loadNrrd(const std::string& path, const VolumeLoadOptions& o) {
    const uint64_t fsz = fileSize(path);
    const std::string head = readTextHead(path, size_t(std::min<uint64_t>(fsz, 1 << 20)));
    if (head.rfind("NRRD000", 0) != 0) throw Error(path, "not a NRRD file (missing NRRD000x magic)");
    std::map<std::string, std::string> kv;
    std::vector<std::string> dataFileList;
    std::string nrrdModality;
    size_t pos = head.find('\n');
    if (pos == std::string::npos) throw Error(path, "truncated NRRD header");
    ++pos;
    bool blank = false, listMode = false;
    while (pos < head.size()) {
        size_t e = head.find('\n', pos);
        if (e == std::string::npos) e = head.size();
        std::string line = head.substr(pos, e - pos);
        pos = e + 1;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (listMode) {
            if (trim(line).empty()) break;
            dataFileList.push_back(trim(line));
            continue;
        }
        if (line.empty()) {
            blank = true;
            break;
        }
        if (line[0] == '#') continue;
        size_t c = line.find(": ");
        if (c == std::string::npos) {
            // key/value pairs: only a modality is used
            if (const size_t kvp = line.find(":="); kvp != std::string::npos) {
                if (lower(trim(line.substr(0, kvp))) == "modality") nrrdModality = line.substr(kvp + 2);
                continue;
            }
            throw Error(path, "bad NRRD header line '" + line.substr(0, 60) + "'");
        }
        const std::string key = lower(trim(line.substr(0, c)));
        const std::string val = trim(line.substr(c + 2));
        kv[key] = val;
        if ((key == "data file" || key == "datafile") &&
            lower(splitWords(val).empty() ? "" : splitWords(val)[0]) == "list")
            listMode = true;
    }
    auto get = [&](const char* k) -> std::string {
        auto it = kv.find(k);
        return it == kv.end() ? std::string() : it->second;
    };
    std::string dataFile = get("data file");
    if (dataFile.empty()) dataFile = get("datafile");
    if (!blank && dataFile.empty()) throw Error(path, "NRRD header not terminated by a blank line");
    if (get("type").empty()) throw Error(path, "NRRD header has no 'type' field");
    if (get("sizes").empty()) throw Error(path, "NRRD header has no 'sizes' field");
    const Src src = parseSrcType(path, get("type"));
    std::vector<int64_t> sizes;
    for (auto& w : splitWords(get("sizes"))) {
        const double v = parseNumber(path, w, "NRRD size");
        if (v != std::floor(v) || std::fabs(v) > 1e15) throw Error(path, "bad NRRD size '" + w + "'");
        sizes.push_back(int64_t(v));
    }
    const std::string dimStr = get("dimension");
    if (!dimStr.empty() && parseNumber(path, dimStr, "dimension") != double(sizes.size()))
        throw Error(path, "NRRD dimension " + dimStr + " does not match " + std::to_string(sizes.size()) + " sizes");
    // A leading axis of size 1 (scalar "kind") is fine.
    if (sizes.size() == 4 && sizes[0] == 1) sizes.erase(sizes.begin());
    VolumeGrid g;
    setDims(g, path, sizes);
    if (const std::string m = modalityTerm(nrrdModality); !m.empty())
        g.meta = {m, "NRRD modality"};
    else if (const std::string w = modalityWord(get("content")); !w.empty())
        g.meta = {w, "NRRD content"};
    if (!get("spacings").empty()) {
        std::vector<double> s;
        for (auto& w : splitWords(get("spacings")))
            if (lower(w) != "nan") s.push_back(parseNumber(path, w, "spacing"));
        if (s.size() >= 3) setSpacing(g, path, {s[s.size() - 3], s[s.size() - 2], s[s.size() - 1]});
    } else if (!get("space directions").empty()) {
        // "(a,b,c) (d,e,f) (g,h,i)": spacing = length of each direction vector
        std::string sd = get("space directions");
        std::vector<double> s;
        size_t p = 0;
        while ((p = sd.find('(', p)) != std::string::npos) {
            size_t q = sd.find(')', p);
            if (q == std::string::npos) throw Error(path, "bad NRRD space directions");
            std::string inner = sd.substr(p + 1, q - p - 1);
            std::replace(inner.begin(), inner.end(), ',', ' ');
            double l2 = 0;
            for (auto& w : splitWords(inner)) {
                const double v = parseNumber(path, w, "space direction");
                l2 += v * v;
            }
            s.push_back(std::sqrt(l2));
            p = q + 1;
        }
        if (s.size() >= 3) setSpacing(g, path, {s[s.size() - 3], s[s.size() - 2], s[s.size() - 1]});
    }
    if (!get("space origin").empty()) {
        std::string so = get("space origin");
        so.erase(std::remove_if(so.begin(), so.end(), [](char c) { return c == '(' || c == ')'; }), so.end());
        std::replace(so.begin(), so.end(), ',', ' ');
        auto w = splitWords(so);
        for (int a = 0; a < 3 && a < int(w.size()); ++a) g.origin[a] = float(parseNumber(path, w[a], "space origin"));
    }
    const std::string enc = lower(get("encoding"));
    bool compressed = false;
    if (enc == "gzip" || enc == "gz")
        compressed = true;
    else if (enc != "raw")
        throw Error(path, "NRRD encoding '" + enc + "' is not supported (raw, gzip)");
    const std::string endian = lower(get("endian"));
    const bool big = endian == "big";
    int64_t byteSkip = 0, lineSkip = 0;
    if (!get("byte skip").empty()) byteSkip = int64_t(parseNumber(path, get("byte skip"), "byte skip"));
    if (!get("line skip").empty()) lineSkip = int64_t(parseNumber(path, get("line skip"), "line skip"));
    if (byteSkip < -1 || lineSkip < 0) throw Error(path, "bad NRRD byte/line skip");
    const uint64_t bytes = g.voxelCount() * uint64_t(srcBytes(src));
    std::vector<std::string> files;
    const fs::path dir = fs::path(path).parent_path();
    auto words = splitWords(dataFile);
    if (dataFile.empty()) {
        files.push_back(path);
    } else if (!words.empty() && lower(words[0]) == "list") {
        for (auto& f : dataFileList) files.push_back((dir / f).string());
    } else if (dataFile.find('%') != std::string::npos && words.size() >= 4) {
        auto index = [&](const std::string& w, const char* what) {
            const double v = parseNumber(path, w, what);
            if (!(std::fabs(v) < 1e9) || v != std::floor(v)) throw Error(path, std::string("bad NRRD ") + what);
            return long(v);
        };
        const long lo = index(words[1], "data file min"), hi = index(words[2], "data file max");
        const long step = index(words[3], "data file step");
        if (step == 0 || (hi - lo) / step < 0 || (hi - lo) / step > 1000000)
            throw Error(path, "bad NRRD data file range");
        // The pattern comes from the file: never hand it to printf (fuzz_volume_headers found a
        // crash with "%s"); only one %d with an optional zero-padded width is accepted.
        const std::string& pat = words[0];
        const size_t pc = pat.find('%');
        size_t q = pc + 1;
        const bool zero = q < pat.size() && pat[q] == '0';
        q += zero;
        int width = 0;
        while (q < pat.size() && std::isdigit(static_cast<unsigned char>(pat[q])) && width < 100)
            width = width * 10 + (pat[q++] - '0');
        if (q >= pat.size() || pat[q] != 'd' || width > 32 || pat.find('%', q) != std::string::npos)
            throw Error(path, "bad NRRD data file pattern '" + pat.substr(0, 64) + "' (one %d expected)");
        for (long i = lo; step > 0 ? i <= hi : i >= hi; i += step) {
            std::string num = std::to_string(i < 0 ? -i : i);
            if (int(num.size()) < width) num.insert(0, size_t(width) - num.size() - (i < 0 ? 1 : 0), zero ? '0' : ' ');
            if (i < 0) num.insert(zero ? 0 : num.find_first_not_of(' '), "-");  // as printf: "-0005", "   -5"
            files.push_back((dir / (pat.substr(0, pc) + num + pat.substr(q + 1))).string());
        }
    } else {
        files.push_back((dir / dataFile).string());
    }
    if (files.empty()) throw Error(path, "NRRD lists no data files");
    if (bytes % files.size() != 0)
        throw Error(path, "NRRD data is not evenly split over " + std::to_string(files.size()) + " files");
    const uint64_t per = bytes / files.size();
    std::vector<Piece> pieces;
    for (const std::string& f : files) {
        Piece p{f, 0, 0, compressed, per};
        if (f == path) {
            // attached data start after the blank line
            p.offset = pos;
        } else if (lineSkip > 0) {
            const std::string h = readTextHead(f, 1 << 16);
            size_t q = 0;
            for (int64_t l = 0; l < lineSkip; ++l) {
                q = h.find('\n', q);
                if (q == std::string::npos) throw Error(f, "line skip beyond the header read");
                ++q;
            }
            p.offset = q;
        }
        if (byteSkip == -1)
            p.skipFromEnd = true;
        else if (compressed)
            p.skip = uint64_t(byteSkip);
        else
            p.offset += uint64_t(byteSkip);
        pieces.push_back(p);
    }
    decodePayload(g, src, big, pieces, path, o.progress);
    return g;
}

// ---- NIfTI-1 ---------------------------------------------------------------------

VolumeGrid loadNifti(const std::string& path, const VolumeLoadOptions& o) {
    const bool gz = endsWith(lower(path), ".gz");
    const uint64_t fsz = fileSize(path);
    uint8_t h[348];
    {
        ByteStream s(path, 0, gz);
        s.read(h, sizeof(h), "NIfTI header");
    }
    int32_t sz;
    std::memcpy(&sz, h, 4);
    bool swap = false;
    if (sz != 348) {
        swap = true;
        sz = loadLE<int32_t>(h, true);
        if (sz != 348) throw Error(path, "not a NIfTI-1 file (sizeof_hdr is not 348)");
    }
    if (std::memcmp(h + 344, "n+1", 4) != 0)
        throw Error(path, std::memcmp(h + 344, "ni1", 4) == 0
                              ? "NIfTI .hdr/.img pairs are not supported; use a single .nii"
                              : "bad NIfTI magic (expected n+1)");
    auto i16 = [&](int off) { return loadLE<int16_t>(h + off, swap); };
    auto f32 = [&](int off) { return loadLE<float>(h + off, swap); };
    const int nd = i16(40);
    if (nd < 1 || nd > 7) throw Error(path, "bad NIfTI dim[0] = " + std::to_string(nd));
    std::vector<int64_t> d = {1, 1, 1};
    for (int a = 0; a < nd; ++a) {
        const int64_t v = i16(42 + 2 * a);
        if (a < 3)
            d[size_t(a)] = v;
        else if (v > 1)
            throw Error(path, "NIfTI with " + std::to_string(nd) + " dimensions (dim[" + std::to_string(a + 1) +
                                  "] = " + std::to_string(v) + "): only 3D volumes are supported");
    }
    VolumeGrid g;
    setDims(g, path, d);
    const int dt = i16(70);
    Src src;
    switch (dt) {
        case 2:
            src = Src::U8;
            break;
        case 4:
            src = Src::I16;
            break;
        case 8:
            src = Src::I32;
            break;
        case 16:
            src = Src::F32;
            break;
        case 64:
            src = Src::F64;
            break;
        case 256:
            src = Src::I8;
            break;
        case 512:
            src = Src::U16;
            break;
        case 768:
            src = Src::U32;
            break;
        default:
            throw Error(path, "unsupported NIfTI datatype " + std::to_string(dt));
    }
    std::vector<double> sp;
    for (int a = 0; a < 3; ++a) {
        const float v = std::fabs(f32(80 + 4 * a));
        sp.push_back(v > 0 && std::isfinite(v) ? v : 1.0);
    }
    setSpacing(g, path, sp);
    const float vox = f32(108);
    if (!std::isfinite(vox) || vox < 348 || vox > float(fsz) * 1100.0f) throw Error(path, "bad NIfTI vox_offset");
    // NIfTI has no modality field; its free-text descrip or aux_file may name one.
    if (const std::string w = modalityWord(headerText(h + 148, 80)); !w.empty())
        g.meta = {w, "NIfTI descrip"};
    else if (const std::string a = modalityWord(headerText(h + 228, 24)); !a.empty())
        g.meta = {a, "NIfTI aux_file"};
    const float slope = f32(112), inter = f32(116);
    if (std::isfinite(slope) && slope != 0.0f) {
        g.scale = slope;
        g.offset = std::isfinite(inter) ? inter : 0.0f;
    }
    const uint64_t bytes = g.voxelCount() * uint64_t(srcBytes(src));
    std::vector<Piece> pieces;
    if (gz)
        pieces.push_back({path, 0, uint64_t(vox), true, bytes});
    else
        pieces.push_back({path, uint64_t(vox), 0, false, bytes});
    decodePayload(g, src, swap, pieces, path, o.progress);
    return g;
}

}  // namespace

uint64_t checkedVoxelCount(const std::string& file, const int64_t dims[3]) {
    uint64_t n = 1;
    for (int a = 0; a < 3; ++a) {
        if (dims[a] <= 0)
            throw Error(file, "bad dimensions " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                  std::to_string(dims[2]) + ": every size must be positive");
        if (uint64_t(dims[a]) > kMaxVoxels || __builtin_mul_overflow(n, uint64_t(dims[a]), &n) || n > kMaxVoxels)
            throw Error(file, "dimensions " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                  std::to_string(dims[2]) + " are too large (at most 2^31-1 voxels are supported)");
    }
    return n;
}

std::array<int, 3> parseDims(const std::string& text) {
    std::string t = text;
    std::replace(t.begin(), t.end(), 'x', ',');
    std::replace(t.begin(), t.end(), ',', ' ');
    auto w = splitWords(t);
    if (w.size() != 3) throw Error("--dims", "expected X,Y,Z, got '" + text + "'");
    int64_t d[3];
    for (int a = 0; a < 3; ++a) {
        const double v = parseNumber("--dims", w[size_t(a)], "size");
        if (v != std::floor(v) || std::fabs(v) > 1e12) throw Error("--dims", "bad size '" + w[size_t(a)] + "'");
        d[a] = int64_t(v);
    }
    checkedVoxelCount("--dims", d);
    return {int(d[0]), int(d[1]), int(d[2])};
}

Vec3f parseSpacing(const std::string& text) {
    std::string t = text;
    std::replace(t.begin(), t.end(), ',', ' ');
    auto w = splitWords(t);
    if (w.size() != 3) throw Error("--spacing", "expected sx,sy,sz, got '" + text + "'");
    Vec3f s;
    for (int a = 0; a < 3; ++a) {
        s[a] = float(parseNumber("--spacing", w[size_t(a)], "spacing"));
        if (!(s[a] > 0)) throw Error("--spacing", "spacing must be positive");
    }
    return s;
}

bool looksLikeVolume(const std::string& path) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        for (auto& e : fs::directory_iterator(path, ec)) {
            const std::string x = lower(e.path().extension().string());
            if (x == ".dcm" || x == ".ima") return true;
        }
        return false;
    }
    const std::string p = lower(path);
    for (const char* e : {".raw", ".mhd", ".mha", ".nrrd", ".nhdr", ".nii", ".nii.gz", ".vdb"})
        if (endsWith(p, e)) return true;
    if (endsWith(p, ".vti")) return true;
    return false;
}

VolumeGrid loadVolume(const std::string& path, const VolumeLoadOptions& opt) {
    const bool dir = requireFileOrDirectory(path);  // before any reader opens it: a FIFO would block
    const std::string p = lower(path);
    VolumeGrid g;
    if (dir)
        g = loadDicomSeries(path, opt);
    else if (opt.dims || !opt.type.empty())
        g = loadRaw(path, opt);
    else if (endsWith(p, ".mhd") || endsWith(p, ".mha"))
        g = loadMetaImage(path, opt);
    else if (endsWith(p, ".nrrd") || endsWith(p, ".nhdr"))
        g = loadNrrd(path, opt);
    else if (endsWith(p, ".nii") || endsWith(p, ".nii.gz"))
        g = loadNifti(path, opt);
    else if (endsWith(p, ".vti"))
        g = loadVTI(path, opt);
    else if (endsWith(p, ".vdb"))
        g = loadVDB(path, opt);
    else if (endsWith(p, ".raw")) {
        // name_XxYxZ_type.raw (the Open SciVis naming) carries dims and type
        VolumeLoadOptions o = opt;
        const std::string stem = fs::path(path).stem().string();
        int x = 0, y = 0, z = 0;
        char type[32] = {};
        const size_t us = stem.find_last_of('_', stem.rfind('_') == std::string::npos ? 0 : stem.rfind('_') - 1);
        if (us != std::string::npos && std::sscanf(stem.c_str() + us + 1, "%dx%dx%d_%31s", &x, &y, &z, type) == 4) {
            o.dims = std::array<int, 3>{x, y, z};
            const std::string t = type;
            o.type = t == "uint8" ? "u8" : t == "uint16" ? "u16" : t == "int16" ? "i16" : t == "float32" ? "f32" : t;
        }
        g = loadRaw(path, o);
    } else
        throw Error(path, "unknown volume format (raw needs --dims and --type)");
    if (opt.spacing) g.spacing = *opt.spacing;
    return g;
}

BrickedVolume loadBrickedVolume(const std::string& path, const VolumeLoadOptions& opt) {
    const bool dir = requireFileOrDirectory(path);
    if (!dir && endsWith(lower(path), ".vdb") && !opt.dims) {
        BrickedVolume v = loadVDBBricked(path, opt);
        if (opt.spacing) v.spacing = *opt.spacing;
        return v;
    }
    VolumeGrid g = loadVolume(path, opt);
    try {
        return brickVolume(g, true);
    } catch (const Error& e) {
        throw Error(path, e.what());
    }
}

void writeRaw(const std::string& path, const VolumeGrid& g) {
    std::ofstream f(path, std::ios::binary);
    if (!f) throw Error(path, "cannot write file");
    f.write(reinterpret_cast<const char*>(g.bytes.data()),
            std::streamsize(g.voxelCount() * size_t(storageBytes(g.storage))));
    if (!f) throw Error(path, "write failed");
}

void writeMetaImage(const std::string& mhdPath, const VolumeGrid& g) {
    const fs::path raw = fs::path(mhdPath).replace_extension(".raw");
    writeRaw(raw.string(), g);
    std::ofstream f(mhdPath);
    if (!f) throw Error(mhdPath, "cannot write file");
    const char* et = g.storage == Storage::U8 ? "MET_UCHAR" : (g.storage == Storage::U16 ? "MET_USHORT" : "MET_FLOAT");
    f << "ObjectType = Image\nNDims = 3\nDimSize = " << g.dims[0] << " " << g.dims[1] << " " << g.dims[2]
      << "\nElementSpacing = " << g.spacing.x << " " << g.spacing.y << " " << g.spacing.z
      << "\nElementByteOrderMSB = False\nElementType = " << et << "\nElementDataFile = " << raw.filename().string()
      << "\n";
}

VolumeSummary summarize(const VolumeGrid& g, int bins) {
    VolumeSummary s;
    const size_t n = g.voxelCount();
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
        const float v = g.value(i);
        if (!std::isfinite(v)) {
            ++s.nonFinite;
            continue;
        }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        sum += v;
    }
    if (lo > hi) lo = hi = 0;
    s.lo = lo;
    s.hi = hi;
    s.mean = n ? sum / double(n) : 0.0;
    s.histogram.assign(size_t(std::max(bins, 1)), 0);
    const float inv = hi > lo ? float(bins) / (hi - lo) : 0.0f;
    for (size_t i = 0; i < n; ++i) {
        const float v = g.value(i);
        if (!std::isfinite(v)) continue;
        s.histogram[size_t(std::min(bins - 1, int((v - lo) * inv)))]++;
    }
    return s;
}

}  // namespace rtfact::volume
