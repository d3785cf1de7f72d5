#include "volume/dicom_modality.h"

#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>

#include "core/util/input_file.h"

namespace rtfact::volume {

namespace {

uint16_t le16(const std::string& b, size_t p) { return uint16_t(uint8_t(b[p]) | (uint8_t(b[p + 1]) << 8)); }
uint32_t le32(const std::string& b, size_t p) { return uint32_t(le16(b, p)) | (uint32_t(le16(b, p + 2)) << 16); }

// VRs whose explicit form has 2 reserved bytes and a 32-bit length.
bool longVR(const char* vr) {
    for (const char* v : {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "SV", "UC", "UN", "UR", "UT", "UV"})
        if (std::memcmp(vr, v, 2) == 0) return true;
    return false;
}

std::string cleanValue(const std::string& v) {
    std::string out;
    for (char c : v) {
        if (c == '\0' || c == ' ') continue;
        if (!std::isalnum(static_cast<unsigned char>(c))) return "";
        out.push_back(char(std::toupper(static_cast<unsigned char>(c))));
    }
    return out.size() <= 16 ? out : "";
}

}  // namespace

std::string parseDicomModality(const std::string& b) {
    if (b.size() < 132 || b.compare(128, 4, "DICM") != 0) return "";
    size_t p = 132;
    bool implicit = false;  // for the data set after group 0002 (which is always explicit)
    while (p + 8 <= b.size()) {
        const uint16_t group = le16(b, p), elem = le16(b, p + 2);
        if (group > 0x0008 || (group == 0x0008 && elem > 0x0060)) return "";
        const bool explicitVR = group == 0x0002 || !implicit;
        uint64_t len;
        size_t value;
        if (explicitVR) {
            const char* vr = b.data() + p + 4;
            if (!std::isupper(static_cast<unsigned char>(vr[0])) || !std::isupper(static_cast<unsigned char>(vr[1])))
                return "";
            if (longVR(vr)) {
                if (p + 12 > b.size()) return "";
                len = le32(b, p + 8);
                value = p + 12;
            } else {
                len = le16(b, p + 6);
                value = p + 8;
            }
        } else {
            len = le32(b, p + 4);
            value = p + 8;
        }
        if (len == 0xFFFFFFFFu || value + len > b.size()) return "";  // undefined length (a sequence) or cut
        const std::string v = b.substr(value, size_t(len));
        if (group == 0x0002 && elem == 0x0010) {
            // Transfer syntax: implicit VR little endian is the only implicit one; explicit
            // big endian (retired) is not walked.
            std::string uid = v;
            while (!uid.empty() && (uid.back() == '\0' || uid.back() == ' ')) uid.pop_back();
            if (uid == "1.2.840.10008.1.2.2") return "";
            implicit = uid == "1.2.840.10008.1.2";
        }
        if (group == 0x0008 && elem == 0x0060) return cleanValue(v);
        p = value + size_t(len);
    }
    return "";
}

std::string readDicomModality(const std::string& path) {
    requireRegularFile(path);  // a FIFO would block the open
    std::ifstream f(path, std::ios::binary);
    if (!f) return "";
    std::string head(1 << 16, '\0');
    f.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(f.gcount()));
    return parseDicomModality(head);
}

}  // namespace rtfact::volume
