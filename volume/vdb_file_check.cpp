// Structural check of an OpenVDB file before OpenVDB reads it (see vdb_file_check.h). The
// walk mirrors what OpenVDB 10 reads (io::File::open, Archive::readGrid, Tree/RootNode/
// InternalNode/LeafNode readTopology and readBuffers, io::readCompressedValues), bounded by
// the region the bytes must lie in: the file, a grid's [gridPos, blockPos) for its metadata,
// transform and topology, [blockPos, endPos) for its buffers.
#include "volume/vdb_file_check.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/util/error.h"
#include "core/util/input_file.h"

namespace rtfact::volume {

namespace {

constexpr int64_t kMagic = 0x56444220;
constexpr uint32_t kMinVersion = 222;  // OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION
constexpr uint32_t kMaxVersion = 224;  // OPENVDB_FILE_VERSION (OpenVDB 10)
constexpr uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;

class Reader {
   public:
    explicit Reader(const std::string& path) : path_(path), f_(path, std::ios::binary) {
        if (!f_) throw Error(path, "cannot open the file");
        f_.seekg(0, std::ios::end);
        const std::streamoff n = f_.tellg();
        if (n < 0) throw Error(path, "cannot read the file");
        size_ = uint64_t(n);
        f_.seekg(0);
        limit_ = size_;
        region_ = "the end of the file";
    }
    uint64_t size() const { return size_; }
    uint64_t pos() const { return pos_; }
    uint64_t left() const { return limit_ - pos_; }
    // Reads are allowed up to `limit` (named `region` in messages).
    void setLimit(uint64_t limit, const char* region) {
        limit_ = limit;
        region_ = region;
    }
    [[noreturn]] void fail(const std::string& what) const {
        throw Error(path_, "corrupt or truncated OpenVDB file: " + what + " (at byte " + std::to_string(pos_) + ")");
    }
    void need(uint64_t n, const char* what) const {
        if (pos_ > limit_ || n > limit_ - pos_)
            fail(std::string(what) + " (" + std::to_string(n) + " bytes) runs past " + region_);
    }
    void seek(uint64_t p) {
        if (p > limit_) fail("offset " + std::to_string(p) + " lies past " + region_);
        pos_ = p;
        f_.clear();
        f_.seekg(std::streamoff(p));
    }
    void read(void* dst, size_t n, const char* what) {
        need(n, what);
        f_.read(static_cast<char*>(dst), std::streamsize(n));
        if (!f_) fail(std::string("read error in ") + what);
        pos_ += n;
    }
    void skip(uint64_t n, const char* what) {
        need(n, what);
        if (n <= 256) {
            char buf[256];
            f_.read(buf, std::streamsize(n));
            if (!f_) fail(std::string("read error in ") + what);
            pos_ += n;
        } else {
            seek(pos_ + n);
        }
    }
    template <class T>
    T get(const char* what) {
        T v;
        read(&v, sizeof(T), what);
        return v;
    }
    // io::readString: uint32 length, then the bytes. Read only if at most maxLen bytes.
    std::string str(const char* what, uint32_t maxLen) {
        const uint32_t n = get<uint32_t>(what);
        need(n, what);
        if (n > maxLen) fail(std::string(what) + " is " + std::to_string(n) + " bytes long");
        std::string s(n, '\0');
        if (n) read(s.data(), n, what);
        return s;
    }
    void skipStr(const char* what) { skip(get<uint32_t>(what), what); }

   private:
    std::string path_;
    std::ifstream f_;
    uint64_t size_ = 0, pos_ = 0, limit_ = 0;
    const char* region_ = "";
};

// Metadata types whose value OpenVDB reads with a fixed size, whatever size the file states.
int fixedMetaSize(const std::string& t) {
    static const std::pair<const char*, int> k[] = {{"bool", 1},   {"float", 4},  {"double", 8}, {"int32", 4},
                                                    {"int64", 8},  {"vec2i", 8},  {"vec2s", 8},  {"vec2d", 16},
                                                    {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
                                                    {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
    for (const auto& [n, s] : k)
        if (t == n) return s;
    return -1;
}

// MetaMap::readMeta: uint32 count, then (name, type name, uint32 size + value) per entry.
void checkMetaMap(Reader& r, const char* what) {
    const uint32_t count = r.get<uint32_t>(what);
    if (uint64_t(count) * 12 > r.left())
        r.fail(std::string(what) + " declares " + std::to_string(count) + " entries, more than the bytes left hold");
    for (uint32_t i = 0; i < count; ++i) {
        r.skipStr("metadata name");
        const std::string type = r.str("metadata type name", 1024);
        const uint32_t n = r.get<uint32_t>("metadata value size");
        r.need(n, "metadata value");
        const int fixed = fixedMetaSize(type);
        if (fixed >= 0 && n != uint32_t(fixed))
            r.fail("metadata of type " + type + " holds " + std::to_string(n) + " bytes, not " + std::to_string(fixed));
        if (type == "__delayedload" && n > 0) {
            // DelayedLoadMetadata::readValue: uint32 count, uint32 size + mask bytes (count bytes
            // when 0), uint32 size + compressed sizes (count int64 when 0, none when 0xffffffff).
            const uint64_t end = r.pos() + n;
            const uint32_t leaves = r.get<uint32_t>("delayed-load metadata");
            if (uint64_t(leaves) * 64 > r.size())
                r.fail("delayed-load metadata declares " + std::to_string(leaves) + " leaves");
            uint64_t used = 12;
            const uint32_t maskBytes = r.get<uint32_t>("delayed-load metadata");
            const uint64_t m = maskBytes > 0 ? maskBytes : leaves;
            if (maskBytes > 0 && maskBytes < 16)
                r.fail("delayed-load metadata holds a " + std::to_string(maskBytes) + "-byte blosc chunk");
            used += m;
            if (used > n) r.fail("delayed-load metadata overruns its " + std::to_string(n) + " bytes");
            r.skip(m, "delayed-load metadata");
            const uint32_t sizeBytes = r.get<uint32_t>("delayed-load metadata");
            if (sizeBytes != 0xffffffffu) {
                const uint64_t c = sizeBytes > 0 ? sizeBytes : uint64_t(leaves) * 8;
                if (sizeBytes > 0 && sizeBytes < 16)
                    r.fail("delayed-load metadata holds a " + std::to_string(sizeBytes) + "-byte blosc chunk");
                used += c;
                if (used > n) r.fail("delayed-load metadata overruns its " + std::to_string(n) + " bytes");
            }
            r.seek(end);
        } else {
            r.skip(n, "metadata value");
        }
    }
}

// Transform::read (format >= 219): map type name, then the map's values.
void checkMap(Reader& r, int depth) {
    const std::string type = r.str("transform map type", 256);
    if (type == "AffineMap" || type == "UnitaryMap")
        r.skip(128, "transform matrix");
    else if (type == "ScaleMap" || type == "UniformScaleMap")
        r.skip(5 * 24, "transform scale");
    else if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap")
        r.skip(6 * 24, "transform scale");
    else if (type == "TranslationMap")
        r.skip(24, "transform translation");
    else if (type == "NonlinearFrustumMap" && depth == 0) {
        r.skip(48 + 16, "frustum transform");
        checkMap(r, 1);
    } else
        r.fail("unknown transform map type '" + type.substr(0, 64) + "'");
}

struct TreeSpec {
    int valueSize = 0;      // bytes of a value (background, tiles, inactive values)
    int dataSize = 0;       // bytes of a value in a node's value array (2 when saved as half)
    std::vector<int> log2;  // internal node levels from the root's children down, then the leaf
};

// "Tree_float_5_4_3" (float and double trees only; other trees are not read by our loaders).
bool parseTree(const std::string& type, bool half, TreeSpec& t) {
    const char* prefixes[][2] = {{"Tree_float_", "4"}, {"Tree_double_", "8"}};
    for (auto& p : prefixes) {
        const std::string pre = p[0];
        if (type.compare(0, pre.size(), pre) != 0) continue;
        t.valueSize = p[1][0] - '0';
        t.dataSize = half ? 2 : t.valueSize;
        t.log2.clear();
        std::string rest = type.substr(pre.size());
        size_t i = 0;
        while (i < rest.size()) {
            size_t j = rest.find('_', i);
            if (j == std::string::npos) j = rest.size();
            const std::string tok = rest.substr(i, j - i);
            if (tok.size() != 1 || tok[0] < '2' || tok[0] > '7') return false;
            t.log2.push_back(tok[0] - '0');
            i = j + 1;
        }
        return t.log2.size() >= 2 && t.log2.size() <= 4;
    }
    return false;
}

class TreeWalk {
   public:
    TreeWalk(Reader& r, const TreeSpec& t, uint32_t compression) : r_(r), t_(t), compression_(compression) {
        leafWords_ = (uint64_t(1) << (3 * t.log2.back())) / 64;
    }

    // Tree::readTopology: int32 buffer count, then RootNode::readTopology.
    void topology() {
        if (r_.get<int32_t>("tree buffer count") != 1) r_.fail("tree buffer count is not 1");
        r_.skip(uint64_t(t_.valueSize), "background value");
        const uint32_t tiles = r_.get<uint32_t>("root tile count");
        const uint32_t children = r_.get<uint32_t>("root child count");
        if (uint64_t(tiles) * uint64_t(13 + t_.valueSize) + uint64_t(children) * 12 > r_.left())
            r_.fail("root declares " + std::to_string(tiles) + " tiles and " + std::to_string(children) +
                    " children, more than the bytes left hold");
        int total = 0;
        for (int l : t_.log2) total += l;
        const int64_t dim = int64_t(1) << total;
        std::set<std::array<int32_t, 3>> keys;
        auto key = [&](const char* what) {
            std::array<int32_t, 3> c;
            r_.read(c.data(), 12, what);
            for (int32_t v : c)
                if (int64_t(v) % dim != 0)
                    r_.fail(std::string(what) + " is not aligned to the root's " + std::to_string(dim) + "-voxel grid");
            if (!keys.insert(c).second) r_.fail(std::string("duplicate ") + what);
            return c;
        };
        for (uint32_t i = 0; i < tiles; ++i) {
            key("root tile origin");
            r_.skip(uint64_t(t_.valueSize), "root tile value");
            if (r_.get<uint8_t>("root tile state") > 1) r_.fail("root tile state is not 0 or 1");
        }
        for (uint32_t i = 0; i < children; ++i) {
            const std::array<int32_t, 3> c = key("root child origin");
            const size_t first = leafMasks_.size();
            internalTopology(0);
            roots_.push_back({c, {first, leafMasks_.size()}});
        }
    }

    // RootNode::readBuffers: the children in coordinate order, their leaves depth first.
    void buffers() {
        std::sort(roots_.begin(), roots_.end());
        std::vector<uint64_t> mask(leafWords_);
        const uint64_t n = leafWords_ * 64;
        for (const auto& root : roots_)
            for (size_t leaf = root.second.first; leaf < root.second.second; leaf += leafWords_) {
                r_.read(mask.data(), leafWords_ * 8, "leaf value mask");
                if (std::memcmp(mask.data(), &leafMasks_[leaf], leafWords_ * 8) != 0)
                    r_.fail("a leaf's value mask differs from the one in the topology");
                compressedValues(n, popcount(mask), "leaf values");
            }
    }

   private:
    static uint64_t popcount(const std::vector<uint64_t>& m) {
        uint64_t c = 0;
        for (uint64_t w : m) c += uint64_t(std::popcount(w));
        return c;
    }

    // InternalNode::readTopology: child mask, value mask, values, then the children.
    void internalTopology(size_t level) {
        const uint64_t n = uint64_t(1) << (3 * t_.log2[level]);
        std::vector<uint64_t> childMask(n / 64), valueMask(n / 64);
        r_.read(childMask.data(), n / 8, "internal node child mask");
        r_.read(valueMask.data(), n / 8, "internal node value mask");
        compressedValues(n, popcount(valueMask), "internal node values");
        const bool leaves = level + 2 == t_.log2.size();
        for (size_t w = 0; w < childMask.size(); ++w)
            for (uint64_t bits = childMask[w]; bits; bits &= bits - 1) {
                if (leaves) {
                    const size_t at = leafMasks_.size();
                    leafMasks_.resize(at + leafWords_);
                    r_.read(&leafMasks_[at], leafWords_ * 8, "leaf value mask");
                } else {
                    internalTopology(level + 1);
                }
            }
    }

    // io::readCompressedValues for n values of which `on` are active.
    void compressedValues(uint64_t n, uint64_t on, const char* what) {
        const uint8_t meta = r_.get<uint8_t>(what);
        if (meta > 6) r_.fail(std::string(what) + ": value-compression flag " + std::to_string(meta) + " is not 0-6");
        if (meta == 2 || meta == 4 || meta == 5) r_.skip(uint64_t(t_.valueSize) * (meta == 5 ? 2 : 1), what);
        if (meta == 3 || meta == 4 || meta == 5) r_.skip(n / 8, what);
        const uint64_t count = (compression_ & kActiveMask) && meta != 6 ? on : n;
        const uint64_t bytes = count * uint64_t(t_.dataSize);
        if (compression_ & (kBlosc | kZip)) {
            const int64_t c = r_.get<int64_t>(what);
            if (c <= 0) {
                if (uint64_t(0) - uint64_t(c) != bytes)
                    r_.fail(std::string(what) + ": a chunk of " + std::to_string(bytes) + " bytes is stored as " +
                            std::to_string(uint64_t(0) - uint64_t(c)) + " bytes");
                r_.skip(bytes, what);
            } else {
                r_.skip(uint64_t(c), what);
            }
        } else {
            r_.skip(bytes, what);
        }
    }

    Reader& r_;
    const TreeSpec& t_;
    uint32_t compression_;
    uint64_t leafWords_ = 1;
    std::vector<uint64_t> leafMasks_;  // every leaf's value mask, in topology order
    std::vector<std::pair<std::array<int32_t, 3>, std::pair<size_t, size_t>>> roots_;  // origin, leaf range
};

}  // namespace

void checkVdbFile(const std::string& path) {
    requireRegularFile(path);  // a FIFO would block the open
    Reader r(path);
    // Archive::readHeader
    if (r.size() < 8 || r.get<int64_t>("magic number") != kMagic)
        throw Error(path, "not an OpenVDB file (bad magic number)");
    const uint32_t version = r.get<uint32_t>("file version");
    if (version < kMinVersion || version > kMaxVersion)
        r.fail("file format version " + std::to_string(version) + " (supported: " + std::to_string(kMinVersion) + "-" +
               std::to_string(kMaxVersion) + ")");
    const uint32_t major = r.get<uint32_t>("library version");
    const uint32_t minor = r.get<uint32_t>("library version");
    if (major < 1 || major > 1000 || minor > 1000)
        r.fail("implausible library version " + std::to_string(major) + "." + std::to_string(minor));
    const uint8_t hasOffsets = r.get<uint8_t>("grid offset flag");
    if (hasOffsets > 1) r.fail("grid offset flag is " + std::to_string(hasOffsets));
    if (!hasOffsets) r.fail("the file has no grid offsets (a VDB stream), which is not supported");
    char uuid[36];
    r.read(uuid, 36, "file UUID");
    for (int i = 0; i < 36; ++i) {
        const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        const char c = uuid[i];
        if (dash ? c != '-' : !((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F')))
            r.fail("malformed file UUID");
    }
    // File::open: file metadata, grid count, grid descriptors (each followed by its grid).
    checkMetaMap(r, "file metadata");
    const int32_t grids = r.get<int32_t>("grid count");
    if (grids < 0 || uint64_t(grids) * 36 > r.left())
        r.fail("grid count " + std::to_string(grids) + " does not fit in the file");
    std::set<std::string> names;
    std::vector<std::string> parents;
    for (int32_t g = 0; g < grids; ++g) {
        r.setLimit(r.size(), "the end of the file");
        // GridDescriptor::read
        const std::string name = r.str("grid name", 1u << 20);
        std::string type = r.str("grid type", 1024);
        const std::string suffix = "_HalfFloat";
        const bool half =
            type.size() > suffix.size() && type.compare(type.size() - suffix.size(), suffix.size(), suffix) == 0;
        if (half) type.resize(type.size() - suffix.size());
        const std::string parent = r.str("instance parent name", 1u << 20);
        const int64_t gridPos = r.get<int64_t>("grid position");
        const int64_t blockPos = r.get<int64_t>("grid block position");
        const int64_t endPos = r.get<int64_t>("grid end position");
        if (gridPos < int64_t(r.pos()) || blockPos < gridPos || endPos < blockPos || uint64_t(endPos) > r.size())
            r.fail("grid '" + name.substr(0, 64) + "' has inconsistent offsets " + std::to_string(gridPos) + ", " +
                   std::to_string(blockPos) + ", " + std::to_string(endPos) + " (file size " +
                   std::to_string(r.size()) + ")");
        names.insert(name);
        if (!parent.empty()) parents.push_back(parent);
        // Archive::readGrid: compression flags, metadata, transform, topology (up to the block
        // position), then the buffers (up to the end position).
        r.seek(uint64_t(gridPos));
        r.setLimit(uint64_t(blockPos), "the grid's block position");
        const uint32_t compression = r.get<uint32_t>("grid compression flags");
        if (compression > (kZip | kActiveMask | kBlosc))
            r.fail("grid compression flags " + std::to_string(compression));
        checkMetaMap(r, "grid metadata");
        checkMap(r, 0);
        TreeSpec spec;
        if (parent.empty() && parseTree(type, half, spec)) {
            TreeWalk walk(r, spec, compression);
            walk.topology();
            r.setLimit(uint64_t(endPos), "the grid's end position");
            r.seek(uint64_t(blockPos));
            walk.buffers();
        }
        r.setLimit(r.size(), "the end of the file");
        r.seek(uint64_t(endPos));
    }
    for (const std::string& p : parents)
        if (!names.count(p)) r.fail("instance parent grid '" + p.substr(0, 64) + "' is not in the file");
}

}  // namespace rtfact::volume
