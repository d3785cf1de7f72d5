// The LAS point records (formats 0-10) decoded into a PointCloud, the extra bytes their
// VLRs describe, the CRS text, and the summary `rtfact info` prints. The header, VLRs
// and EVLRs come from points/las_header.h; LAZ records from points/laz_decoder.h.
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "points/las_header.h"

namespace rtfact::points::las {

// One scalar of the Extra Bytes VLRs ("LASF_Spec" 4): arrays of the deprecated types
// become NAME[0], NAME[1] ...; undocumented bytes (type 0) are skipped but take room.
struct ExtraField {
    std::string name;
    uint8_t type = 0;     // 1-10: u8 i8 u16 i16 u32 i32 u64 i64 f32 f64
    uint32_t offset = 0;  // in the record
    double scale = 1, add = 0;
};

// Bytes of each data type 1-10 (0 for others).
int extraTypeSize(int type);

// The fields of every Extra Bytes VLR in file order, placed after the format's standard
// bytes; throws Error(source, ...) when a VLR is malformed or describes more bytes than the
// records have.
std::vector<ExtraField> parseExtraBytes(const Header& h, std::span<const uint8_t> file, const std::string& source);

// The coordinate reference system as text: the WKT VLR/EVLR, else the GeoTIFF keys
// (model type, EPSG codes); empty when the file has none.
std::string crsText(const Header& h, std::span<const uint8_t> file);

// What `rtfact info` prints of a LAS/LAZ file (counts by return and class come from the
// points themselves).
struct Summary {
    Header header;
    std::string crs;
    std::map<int, uint64_t> byClass, byReturn;
    std::vector<ExtraField> extra;
};
Summary summarize(const std::string& file);

}  // namespace rtfact::points::las
