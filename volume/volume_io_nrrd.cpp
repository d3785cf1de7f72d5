// NRRD (.nrrd/.nhdr): raw or gzip data, attached or detached, file lists and patterns.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
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
    const ScalarType src = parseVoxelType(path, get("type"));
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
    const uint64_t bytes = g.voxelCount() * uint64_t(io::scalarBytes(src));
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
    decodePayload(g, src, big, pieces, path, o);
    return g;
}

}  // namespace rtfact::volume
