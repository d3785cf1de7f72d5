// Legacy VTK POLYDATA validation: see vtk_legacy_check.h. The walk follows what
// vtkPolyDataReader / vtkDataReader (VTK 9.1) read, token by token: keywords and counts
// are whitespace-separated tokens; in BINARY files the rest of the line after an array
// header is skipped and the values follow as big-endian bytes. Keywords are matched
// case-insensitively (VTK lower-cases them), but exactly (VTK compares prefixes): a
// mangled keyword is rejected rather than guessed.
#include "surfaces/vtk_legacy_check.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include "core/io/file_helpers.h"
#include "core/util/error.h"

namespace rtfact::surfaces {
namespace {

constexpr uint64_t kMaxCount = uint64_t(std::numeric_limits<int64_t>::max());
constexpr size_t kMaxToken = 255;  // VTK reads keywords into char[256]

std::string upper(std::string s) {
    for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
    return s;
}
bool isSpace(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// A token quoted for an error message: printable, at most 40 characters.
std::string quote(const std::string& s) {
    std::string q = "'";
    for (size_t i = 0; i < s.size() && i < 40; ++i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        q += (c >= 0x20 && c < 0x7f) ? char(c) : '?';
    }
    if (s.size() > 40) q += "...";
    return q + "'";
}
std::string str(uint64_t v) { return std::to_string(v); }

// Buffered reader over the file: byte access, absolute seeks, whitespace tokens.
class Source {
   public:
    explicit Source(const std::string& file) : file_(file) {
        std::error_code ec;
        size_ = std::filesystem::file_size(file, ec);
        if (ec) throw Error(file, "cannot read file (" + ec.message() + ")");
        f_ = std::fopen(file.c_str(), "rb");
        if (!f_) throw Error(file, "cannot open file");
        buf_.resize(1 << 16);
    }
    ~Source() { std::fclose(f_); }
    Source(const Source&) = delete;
    Source& operator=(const Source&) = delete;

    [[noreturn]] void fail(const std::string& what) const { throw Error(file_, what); }

    uint64_t size() const { return size_; }
    uint64_t tell() const { return start_ + pos_; }
    uint64_t remaining() const { return size_ > tell() ? size_ - tell() : 0; }
    int peek() {
        if (pos_ == len_ && !fill()) return EOF;
        return static_cast<unsigned char>(buf_[pos_]);
    }
    int get() {
        const int c = peek();
        if (c != EOF) ++pos_;
        return c;
    }
    void seek(uint64_t p) {
        if (p >= start_ && p <= start_ + len_) {
            pos_ = size_t(p - start_);
            return;
        }
        if (fseeko(f_, off_t(p), SEEK_SET) != 0) fail("cannot seek to byte " + str(p));
        start_ = p;
        pos_ = len_ = 0;
    }

    // Next whitespace-separated token; false at the end of the file. newline: whether a
    // line break was skipped before it.
    bool token(std::string& t, bool* newline = nullptr) {
        t.clear();
        int c;
        bool nl = false;
        while ((c = peek()) != EOF && isSpace(c)) {
            nl |= c == '\n';
            ++pos_;
        }
        if (newline) *newline = nl;
        if (c == EOF) return false;
        const uint64_t at = tell();
        while ((c = peek()) != EOF && !isSpace(c)) {
            if (t.size() == kMaxToken) fail("token longer than " + str(kMaxToken) + " characters at byte " + str(at));
            t.push_back(char(c));
            ++pos_;
        }
        return true;
    }
    // The token after the current position, without consuming it.
    bool peekToken(std::string& t, bool* newline = nullptr) {
        const uint64_t at = tell();
        bool ok;
        try {
            ok = token(t, newline);
        } catch (const Error&) {
            ok = false;  // too long: not a keyword
            t.clear();
        }
        seek(at);
        return ok;
    }
    // Line up to '\n' (consumed, '\r' stripped), keeping at most `keep` characters.
    bool line(std::string& l, size_t keep) {
        l.clear();
        int c;
        while ((c = get()) != EOF && c != '\n')
            if (l.size() < keep) l.push_back(char(c));
        if (!l.empty() && l.back() == '\r') l.pop_back();
        return c == '\n';
    }

   private:
    bool fill() {
        start_ += len_;
        pos_ = 0;
        len_ = std::fread(buf_.data(), 1, buf_.size(), f_);
        return len_ > 0;
    }
    std::string file_;
    std::FILE* f_ = nullptr;
    uint64_t size_ = 0;
    std::vector<char> buf_;
    uint64_t start_ = 0;  // file offset of buf_[0]; the FILE position is start_ + len_
    size_t pos_ = 0, len_ = 0;
};

struct ValueType {
    std::string name;
    int bytes = 4;
    bool integer = false;
    bool isSigned = true;
};

VtkLegacyHeader parseHeader(Source& s) {
    VtkLegacyHeader h;
    std::string l;
    const bool nl = s.line(l, 256);
    static const char kMagic[] = "# vtk DataFile Version";
    if (l.compare(0, sizeof(kMagic) - 1, kMagic) != 0) return h;
    h.vtk = true;
    if (!nl) s.fail("truncated VTK header: the file ends in the version line");
    if (std::sscanf(l.c_str() + sizeof(kMagic) - 1, "%d.%d", &h.major, &h.minor) != 2) h.major = h.minor = 0;
    if (!s.line(l, 0)) s.fail("truncated VTK header: the file ends in the title line");
    std::string t;
    if (!s.token(t)) s.fail("truncated VTK header: no ASCII or BINARY line");
    const std::string fmt = io::lower(t);
    if (fmt == "binary")
        h.binary = true;
    else if (fmt != "ascii")
        s.fail("VTK header: unknown file format " + quote(t) + " (ASCII or BINARY expected)");
    if (!s.token(t)) s.fail("truncated VTK header: no DATASET line");
    h.firstKeyword = upper(t);
    if (h.firstKeyword == "DATASET") {
        if (!s.token(t)) s.fail("truncated VTK header: no dataset type after DATASET");
        h.dataset = upper(t);
    }
    return h;
}

class Walker {
   public:
    Walker(Source& s, const VtkLegacyHeader& h) : s_(s), binary_(h.binary), newCells_(h.major >= 5) {}

    VtkLegacySummary run() {
        std::string kw;
        // Geometry, then attributes (VTK reads POINT_DATA / CELL_DATA to the end).
        while (s_.token(kw)) {
            const std::string k = upper(kw);
            if (k == "POINTS")
                points();
            else if (k == "VERTICES" || k == "LINES" || k == "POLYGONS" || k == "TRIANGLE_STRIPS")
                cells(k);
            else if (k == "FIELD")
                field("FIELD");
            else if (k == "METADATA")
                metadata();
            else if (k == "POINT_DATA" || k == "CELL_DATA") {
                attributes(k);
                break;
            } else
                fail("unsupported legacy VTK section " + quote(kw));
        }
        if (!havePoints_) fail("POLYDATA file without a POINTS section");
        if (haveIndex_ && maxIndex_ >= sum_.points)
            fail("cells refer to point " + str(maxIndex_) + " but POINTS declares " + str(sum_.points));
        return sum_;
    }

   private:
    [[noreturn]] void fail(const std::string& what) const { s_.fail(what); }

    uint64_t mul(uint64_t a, uint64_t b, const std::string& what) const {
        uint64_t r;
        if (__builtin_mul_overflow(a, b, &r) || r > kMaxCount)
            fail(what + ": value count overflows (" + str(a) + " x " + str(b) + ")");
        return r;
    }

    // A non-negative integer header field, at most `max`.
    uint64_t count(const std::string& what, uint64_t max = kMaxCount) {
        std::string t;
        if (!s_.token(t)) fail("truncated file: it ends before " + what);
        const char* b = t.data();
        const char* e = t.data() + t.size();
        if (b != e && *b == '+') ++b;
        if (b != e && *b == '-') fail(what + " is negative (" + quote(t) + ")");
        uint64_t v = 0;
        const auto r = std::from_chars(b, e, v);
        if (b == e || r.ptr != e || r.ec == std::errc::invalid_argument)
            fail(what + ": expected a count, found " + quote(t));
        if (r.ec == std::errc::result_out_of_range || v > max) fail(what + " is too large (" + quote(t) + ")");
        return v;
    }

    std::string word(const std::string& what) {
        std::string t;
        if (!s_.token(t)) fail("truncated file: it ends before " + what);
        return t;
    }

    ValueType type(const std::string& what) {
        const std::string t = word(what + " data type");
        const std::string n = io::lower(t);
        ValueType v;
        v.name = n;
        if (n == "char" || n == "signed_char")
            v = {n, 1, true, true};
        else if (n == "unsigned_char")
            v = {n, 1, true, false};
        else if (n == "short")
            v = {n, 2, true, true};
        else if (n == "unsigned_short")
            v = {n, 2, true, false};
        else if (n == "int" || n == "vtkidtype")
            v = {n, 4, true, true};  // vtkIdType is written as int
        else if (n == "unsigned_int")
            v = {n, 4, true, false};
        else if (n == "long" || n == "vtktypeint64")
            v = {n, 8, true, true};
        else if (n == "unsigned_long" || n == "vtktypeuint64")
            v = {n, 8, true, false};
        else if (n == "float")
            v = {n, 4, false, true};
        else if (n == "double")
            v = {n, 8, false, true};
        else if (n == "bit")
            fail(what + ": 'bit' arrays are not supported");
        else if (n == "string" || n == "utf8_string" || n == "variant")
            fail(what + ": " + quote(t) + " arrays are not supported");
        else
            fail(what + ": unknown data type " + quote(t));
        return v;
    }

    // BINARY: VTK skips the rest of the header line, then reads the values.
    void endHeaderLine(const std::string& what) {
        int c;
        while ((c = s_.get()) != EOF && c != '\n')
            if (c != ' ' && c != '\t' && c != '\r')
                fail(what + ": unexpected byte after the header line, before the binary data");
        if (c == EOF) fail("truncated file: " + what + " has no binary data after its header line");
    }

    void needBytes(const std::string& what, uint64_t n, const ValueType& t) {
        const uint64_t bytes = mul(n, uint64_t(t.bytes), what);
        if (bytes > s_.remaining())
            fail("truncated or lying file: " + what + " declares " + str(n) + " values (" + str(bytes) +
                 " bytes) but only " + str(s_.remaining()) + " bytes follow");
    }

    bool numberToken(const std::string& t, bool integer) const {
        const char* b = t.data();
        const char* e = t.data() + t.size();
        if (b != e && *b == '+') ++b;
        if (b == e) return false;
        if (integer) {
            if (*b == '-') ++b;
            return b != e && std::all_of(b, e, [](char c) { return c >= '0' && c <= '9'; });
        }
        double v;
        const auto r = std::from_chars(b, e, v);
        return r.ptr == e && (r.ec == std::errc() || r.ec == std::errc::result_out_of_range);
    }

    // Scans `n` values of type t without storing them.
    void values(const std::string& what, uint64_t n, const ValueType& t) {
        if (n == 0) return;
        if (binary_) {
            endHeaderLine(what);
            needBytes(what, n, t);
            s_.seek(s_.tell() + n * uint64_t(t.bytes));
        } else {
            std::string tok;
            for (uint64_t i = 0; i < n; ++i) {
                if (!s_.token(tok))
                    fail("truncated or lying file: " + what + " declares " + str(n) +
                         " values but the file ends after " + str(i));
                if (!numberToken(tok, t.integer))
                    fail(what + ": value " + str(i + 1) + " of " + str(n) + " is " + quote(tok) + ", not " +
                         (t.integer ? "an integer" : "a number"));
            }
        }
        arrayTail();
    }

    // One integer value (binary: big-endian of t.bytes; the bytes were checked to be there).
    int64_t integer(const std::string& what, uint64_t i, uint64_t n, const ValueType& t) {
        if (binary_) {
            uint64_t u = 0;
            for (int b = 0; b < t.bytes; ++b) u = (u << 8) | uint64_t(s_.get());
            if (t.isSigned && t.bytes < 8 && (u >> (8 * t.bytes - 1)) & 1) u |= ~uint64_t(0) << (8 * t.bytes);
            if (!t.isSigned && u > kMaxCount) fail(what + ": value " + str(i + 1) + " is out of range");
            return int64_t(u);
        }
        std::string tok;
        if (!s_.token(tok))
            fail("truncated or lying file: " + what + " declares " + str(n) + " values but the file ends after " +
                 str(i));
        const char* b = tok.data();
        const char* e = tok.data() + tok.size();
        if (b != e && *b == '+') ++b;
        int64_t v = 0;
        const auto r = std::from_chars(b, e, v);
        if (b == e || r.ptr != e || r.ec == std::errc::invalid_argument)
            fail(what + ": value " + str(i + 1) + " of " + str(n) + " is " + quote(tok) + ", not an integer");
        if (r.ec == std::errc::result_out_of_range)
            fail(what + ": value " + str(i + 1) + " (" + quote(tok) + ") is out of range");
        if (t.bytes == 4 && (v < std::numeric_limits<int32_t>::min() || v > std::numeric_limits<int32_t>::max()))
            fail(what + ": value " + str(i + 1) + " (" + quote(tok) + ") does not fit a 32-bit int");
        return v;
    }

    // A point index of cell (or connectivity value) `n` of section `what`.
    void pointIndex(const std::string& what, const char* unit, uint64_t n, int64_t idx) {
        if (idx < 0) fail(what + ": " + unit + " " + str(n) + " refers to point " + std::to_string(idx));
        if (havePoints_ && uint64_t(idx) >= sum_.points)
            fail(what + ": " + unit + " " + str(n) + " refers to point " + std::to_string(idx) +
                 " but POINTS declares " + str(sum_.points));
        maxIndex_ = std::max(maxIndex_, uint64_t(idx));
        haveIndex_ = true;
    }

    void addCells(uint64_t n, const std::string& what) {
        if (__builtin_add_overflow(sum_.cells, n, &sum_.cells) || sum_.cells > kMaxCount)
            fail(what + ": cell count overflows");
    }

    // After an array VTK pops blank lines and an optional METADATA block.
    void arrayTail() {
        std::string t;
        if (s_.peekToken(t) && upper(t) == "METADATA") {
            s_.token(t);
            metadata();
        }
    }
    // METADATA: skipped up to the next empty line (or the end of the file).
    void metadata() {
        std::string l;
        s_.line(l, 0);  // rest of the METADATA line
        while (s_.line(l, 1) && !l.empty()) {
        }
    }

    void points() {
        if (havePoints_) fail("second POINTS section");
        const uint64_t n = count("the POINTS count");
        const ValueType t = type("POINTS");
        sum_.points = n;
        havePoints_ = true;
        if (haveIndex_ && maxIndex_ >= n)
            fail("cells refer to point " + str(maxIndex_) + " but POINTS declares " + str(n));
        values("POINTS", mul(n, 3, "POINTS"), t);
    }

    void cells(const std::string& k) {
        if (std::find(seenCells_.begin(), seenCells_.end(), k) != seenCells_.end()) fail("second " + k + " section");
        seenCells_.push_back(k);
        if (newCells_) return cellsOffsets(k);
        // Legacy form: "K n size", then size ints: per cell a point count, then the points.
        const uint64_t n = count(k + " cell count");
        const uint64_t size = count(k + " size");
        const ValueType t{"int", 4, true, true};
        if (binary_) {
            endHeaderLine(k);
            needBytes(k, size, t);
        }
        uint64_t i = 0, cell = 0;
        while (i < size) {
            const int64_t pts = integer(k, i++, size, t);
            if (pts < 0) fail(k + ": cell " + str(cell) + " has a negative point count (" + std::to_string(pts) + ")");
            if (uint64_t(pts) > size - i)
                fail(k + ": cell " + str(cell) + " declares " + std::to_string(pts) + " points but only " +
                     str(size - i) + " of the " + str(size) + " declared values remain");
            for (int64_t j = 0; j < pts; ++j) pointIndex(k, "cell", cell, integer(k, i++, size, t));
            ++cell;
        }
        if (cell != n) fail(k + " declares " + str(n) + " cells but its " + str(size) + " values hold " + str(cell));
        addCells(cell, k);
    }

    // VTK 5.x form: "K noffsets nconn", "OFFSETS type" + noffsets values, "CONNECTIVITY
    // type" + nconn values.
    void cellsOffsets(const std::string& k) {
        const uint64_t nOff = count(k + " offset count");
        const uint64_t nConn = count(k + " connectivity size");
        if (nOff == 0) return;  // VTK reads nothing more
        std::string t = word(k + " OFFSETS");
        if (upper(t) != "OFFSETS") fail(k + ": expected OFFSETS, found " + quote(t));
        const std::string wo = k + " OFFSETS";
        const ValueType to = type(wo);
        if (!to.integer) fail(wo + ": offsets must be integers, not " + to.name);
        if (binary_) {
            endHeaderLine(wo);
            needBytes(wo, nOff, to);
        }
        int64_t prev = 0;
        for (uint64_t i = 0; i < nOff; ++i) {
            const int64_t o = integer(wo, i, nOff, to);
            if (i == 0 && o != 0) fail(wo + ": the first offset is " + std::to_string(o) + ", not 0");
            if (o < prev)
                fail(wo + ": offset " + str(i) + " (" + std::to_string(o) + ") is smaller than the one before");
            if (uint64_t(o) > nConn)
                fail(wo + ": offset " + str(i) + " (" + std::to_string(o) + ") is past the connectivity size " +
                     str(nConn));
            prev = o;
        }
        if (uint64_t(prev) != nConn)
            fail(wo + ": the last offset is " + std::to_string(prev) + ", not the connectivity size " + str(nConn));
        arrayTail();
        t = word(k + " CONNECTIVITY");
        if (upper(t) != "CONNECTIVITY") fail(k + ": expected CONNECTIVITY, found " + quote(t));
        const std::string wc = k + " CONNECTIVITY";
        const ValueType tc = type(wc);
        if (!tc.integer) fail(wc + ": point indices must be integers, not " + tc.name);
        if (nConn > 0) {
            if (binary_) {
                endHeaderLine(wc);
                needBytes(wc, nConn, tc);
            }
            for (uint64_t i = 0; i < nConn; ++i) pointIndex(wc, "value", i + 1, integer(wc, i, nConn, tc));
            arrayTail();
        }
        addCells(nOff - 1, k);
    }

    // FIELD name k, then k arrays "name ncomp ntuples type" and their values.
    void field(const std::string& where) {
        word(where + " name");
        const uint64_t k = count(where + " array count", uint64_t(std::numeric_limits<int32_t>::max()));
        for (uint64_t a = 0; a < k; ++a) {
            const std::string name = word(where + " array " + str(a + 1) + " name");
            if (name == "NULL_ARRAY") continue;
            const std::string what = where + " array " + quote(name);
            const uint64_t nc = count(what + " component count", uint64_t(std::numeric_limits<int32_t>::max()));
            const uint64_t nt = count(what + " tuple count");
            const ValueType t = type(what);
            if (nc == 0) fail(what + ": zero components");
            values(what, mul(nc, nt, what), t);
        }
    }

    // POINT_DATA n / CELL_DATA n and the attribute sections after it, to the end.
    void attributes(std::string k) {
        constexpr uint64_t kInt = uint64_t(std::numeric_limits<int32_t>::max());
        std::string kw;
        for (;;) {
            const bool pointData = k == "POINT_DATA";
            const uint64_t n = count(k + " count");
            const uint64_t expect = pointData ? sum_.points : sum_.cells;
            if (n != expect)
                fail(k + " declares " + str(n) + " values but the file has " + str(expect) +
                     (pointData ? " points" : " cells"));
            for (;;) {
                if (!s_.token(kw)) return;
                const std::string a = upper(kw);
                if (a == "POINT_DATA" || a == "CELL_DATA") {
                    k = a;
                    break;
                }
                const std::string where = k + " " + a;
                if (a == "SCALARS") {
                    const std::string name = word(where + " name");
                    const std::string what = where + " " + quote(name);
                    const ValueType t = type(what);
                    uint64_t nc = 1;
                    std::string next;
                    bool newline = false;
                    if (s_.peekToken(next, &newline) && upper(next) != "LOOKUP_TABLE" && !newline) {
                        nc = count(what + " component count", kInt);
                        if (nc == 0) fail(what + ": zero components");
                    }
                    if (s_.peekToken(next) && upper(next) == "LOOKUP_TABLE") {
                        s_.token(next);
                        word(what + " lookup table name");
                    }
                    values(what, mul(n, nc, what), t);
                } else if (a == "COLOR_SCALARS") {
                    const std::string what = where + " " + quote(word(where + " name"));
                    const uint64_t nc = count(what + " component count", kInt);
                    if (nc == 0) fail(what + ": zero components");
                    values(what, mul(n, nc, what),
                           binary_ ? ValueType{"unsigned_char", 1, true, false} : ValueType{"float", 4, false, true});
                } else if (a == "LOOKUP_TABLE") {
                    const std::string what = where + " " + quote(word(where + " name"));
                    const uint64_t size = count(what + " size", kInt);
                    values(what, mul(size, 4, what),
                           binary_ ? ValueType{"unsigned_char", 1, true, false} : ValueType{"float", 4, false, true});
                } else if (a == "VECTORS" || a == "NORMALS" || a == "TENSORS" || a == "TENSORS6" || a == "GLOBAL_IDS" ||
                           a == "PEDIGREE_IDS" || (a == "EDGE_FLAGS" && pointData)) {
                    const std::string what = where + " " + quote(word(where + " name"));
                    const ValueType t = type(what);
                    const uint64_t per = a == "VECTORS" || a == "NORMALS" ? 3
                                         : a == "TENSORS"                 ? 9
                                         : a == "TENSORS6"                ? 6
                                                                          : 1;
                    values(what, mul(n, per, what), t);
                } else if (a == "TEXTURE_COORDINATES") {
                    const std::string what = where + " " + quote(word(where + " name"));
                    const uint64_t dim = count(what + " dimension", kInt);
                    if (dim < 1 || dim > 3) fail(what + ": dimension " + str(dim) + " (1 to 3 expected)");
                    const ValueType t = type(what);
                    values(what, mul(n, dim, what), t);
                } else if (a == "FIELD") {
                    field(where);
                } else if (a == "METADATA") {
                    metadata();
                } else if (a == "POINTS" || a == "VERTICES" || a == "LINES" || a == "POLYGONS" ||
                           a == "TRIANGLE_STRIPS") {
                    fail(a + " section after " + k + " (VTK reads no geometry after the attribute data)");
                } else {
                    fail("unsupported legacy VTK section " + quote(kw) + " in " + k);
                }
            }
        }
    }

    Source& s_;
    bool binary_;
    bool newCells_;  // file version >= 5: OFFSETS / CONNECTIVITY cell arrays
    VtkLegacySummary sum_;
    bool havePoints_ = false, haveIndex_ = false;
    uint64_t maxIndex_ = 0;
    std::vector<std::string> seenCells_;
};

}  // namespace

VtkLegacyHeader readVtkLegacyHeader(const std::string& file) {
    Source s(file);
    return parseHeader(s);
}

VtkLegacySummary validateVtkLegacyPolyData(const std::string& file) {
    Source s(file);
    const VtkLegacyHeader h = parseHeader(s);
    if (!h.vtk) s.fail("not a VTK legacy file (missing '# vtk DataFile Version' line)");
    if (h.dataset != "POLYDATA")
        s.fail("VTK legacy file is not POLYDATA (" + quote(h.firstKeyword + " " + h.dataset) + ")");
    return Walker(s, h).run();
}

}  // namespace rtfact::surfaces
