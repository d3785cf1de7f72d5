// The LAS public header block, its variable-length records (VLRs) and extended VLRs
// (EVLRs), read from a mapped .las/.laz file and checked against the file before anything
// is allocated for the points (ASPRS LAS 1.0-1.4).
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rtfact::points::las {

struct Vlr {
    std::string userId;  // NUL padding stripped
    uint16_t recordId = 0;
    std::string description;
    uint64_t offset = 0;  // of the payload, in the file
    uint64_t size = 0;    // of the payload
    bool extended = false;
};

struct Header {
    uint8_t versionMajor = 0, versionMinor = 0;
    uint16_t fileSourceId = 0, globalEncoding = 0;
    std::string systemId, software;
    uint16_t headerSize = 0;
    uint32_t pointDataOffset = 0;
    uint8_t pointFormat = 0;  // 0-10, the compression bits removed
    bool compressed = false;  // LAZ: bit 7 (or 6) of the format byte was set
    uint16_t recordLength = 0;
    uint64_t pointCount = 0;  // the 64-bit count of LAS 1.4 when set, else the legacy one
    std::array<uint64_t, 15> pointsByReturn{};
    std::array<double, 3> scale{}, offset{}, min{}, max{};
    uint64_t waveformOffset = 0;  // LAS 1.3+
    std::vector<Vlr> vlrs;        // VLRs, then EVLRs
};

// Bytes of a record of each point data format (the record may be longer: extra bytes).
uint16_t minimumRecordLength(int pointFormat);

// Parses and validates the header and walks every VLR and EVLR; throws
// Error(source, ...) naming the first inconsistency (bad signature, version, sizes,
// records that leave the file, point data longer than the file ...).
Header readHeader(std::span<const uint8_t> file, const std::string& source);

// The first VLR/EVLR with this user id and record id, or nullptr.
const Vlr* findVlr(const Header& h, std::string_view userId, uint16_t recordId);

// A VLR's payload inside the file it was read from.
inline std::span<const uint8_t> payload(std::span<const uint8_t> file, const Vlr& v) {
    return file.subspan(v.offset, v.size);
}

}  // namespace rtfact::points::las
