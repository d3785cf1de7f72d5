// MetaImage (.mhd header with a detached or local data file, .mha).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/io/file_helpers.h"
#include "core/io/scalar_type.h"
#include "core/util/error.h"
#include "volume/volume_io.h"
#include "volume/volume_io_detail.h"

namespace rtfact::volume {

namespace fs = std::filesystem;
using namespace detail;
using io::fileSize;
using io::lower;
using io::ScalarType;

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
    const ScalarType src = parseVoxelType(path, get("elementtype"));
    std::string msb = lower(get("elementbyteordermsb"));
    if (msb.empty()) msb = lower(get("binarydatabyteordermsb"));
    const bool big = msb == "true" || msb == "1";
    const bool compressed = lower(get("compresseddata")) == "true";
    if (const std::string m = modalityTerm(get("modality")); !m.empty()) g.meta = {m, "MetaImage Modality"};
    const std::string df = get("elementdatafile");
    const uint64_t bytes = g.voxelCount() * uint64_t(io::scalarBytes(src));
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
    decodePayload(g, src, big, pieces, path, o);
    return g;
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

}  // namespace rtfact::volume
