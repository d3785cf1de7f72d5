// Compressor 2 items, version 2. Every field is predicted from the previous point:
// X and Y from the median of the last five differences of points with the same return
// map, Z from the last Z of the same return level, intensity from the last of the same
// return map; the small fields by adaptive symbol models keyed by their previous value.
#include "points/laz_point10.h"

#include <array>
#include <cstring>
#include <memory>
#include <vector>

#include "core/util/error.h"
#include "points/laz_arithmetic_decoder.h"
#include "points/laz_items.h"

namespace rtfact::points::laz {

namespace {

// Context tables indexed by [number of returns][return number] (3 bits each): a serial
// number of the (r, n) combination, and the number of returns before this one.
constexpr uint8_t kReturnMap[8][8] = {{15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
                                      {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
                                      {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
                                      {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
constexpr uint8_t kReturnLevel[8][8] = {{0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5},
                                        {3, 2, 1, 0, 1, 2, 3, 4}, {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2},
                                        {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

// POINT10 record: X Y Z (i32), intensity (u16), return bits, classification, scan angle
// rank (i8), user data, point source id (u16).
class Point10Decoder {
   public:
    void init(const uint8_t* raw) {
        std::memcpy(last_, raw, 20);
        x_ = int32_t(loadU32(raw));
        y_ = int32_t(loadU32(raw + 4));
    }

    void read(ArithmeticDecoder& dec, uint8_t* out) {
        uint32_t r, n, m, l;
        uint16_t intensity;
        const uint32_t changed = dec.decodeSymbol(changedValues_);
        if (changed) {
            if (changed & 32) last_[14] = uint8_t(dec.decodeSymbol(bitByte_[last_[14]]));
            r = last_[14] & 7;
            n = (last_[14] >> 3) & 7;
            m = kReturnMap[n][r];
            l = kReturnLevel[n][r];
            if (changed & 16) {
                intensity = uint16_t(icIntensity_.decompress(dec, lastIntensity_[m], m < 3 ? m : 3));
                lastIntensity_[m] = intensity;
            } else {
                intensity = lastIntensity_[m];
            }
            if (changed & 8) last_[15] = uint8_t(dec.decodeSymbol(classification_[last_[15]]));
            if (changed & 4) {
                const uint32_t v = dec.decodeSymbol(scanAngle_[(last_[14] >> 6) & 1]);
                last_[16] = uint8_t(v + last_[16]);
            }
            if (changed & 2) last_[17] = uint8_t(dec.decodeSymbol(userData_[last_[17]]));
            if (changed & 1) {
                const uint16_t id = uint16_t(icSourceId_.decompress(dec, loadU16(last_ + 18)));
                std::memcpy(last_ + 18, &id, 2);
            }
        } else {
            r = last_[14] & 7;
            n = (last_[14] >> 3) & 7;
            m = kReturnMap[n][r];
            l = kReturnLevel[n][r];
            intensity = lastIntensity_[m];
        }
        std::memcpy(last_ + 12, &intensity, 2);

        int32_t diff = icDx_.decompress(dec, medianX_[m].get(), n == 1);
        x_ = int32_t(uint32_t(x_) + uint32_t(diff));
        medianX_[m].add(diff);
        uint32_t k = icDx_.k();
        diff = icDy_.decompress(dec, medianY_[m].get(), (n == 1) + (k < 20 ? (k & ~1u) : 20));
        y_ = int32_t(uint32_t(y_) + uint32_t(diff));
        medianY_[m].add(diff);
        k = (icDx_.k() + icDy_.k()) / 2;
        const int32_t z = icZ_.decompress(dec, lastHeight_[l], (n == 1) + (k < 18 ? (k & ~1u) : 18));
        lastHeight_[l] = z;
        std::memcpy(last_, &x_, 4);
        std::memcpy(last_ + 4, &y_, 4);
        std::memcpy(last_ + 8, &z, 4);
        std::memcpy(out, last_, 20);
    }

   private:
    uint8_t last_[20];
    int32_t x_ = 0, y_ = 0;
    uint16_t lastIntensity_[16] = {};
    int32_t lastHeight_[8] = {};
    StreamingMedian5 medianX_[16], medianY_[16];
    SymbolModel changedValues_{64};
    IntegerDecompressor icIntensity_{16, 4};
    SymbolModel scanAngle_[2] = {SymbolModel(256), SymbolModel(256)};
    IntegerDecompressor icSourceId_{16};
    LazySymbolModels bitByte_{256, 256}, classification_{256, 256}, userData_{256, 256};
    IntegerDecompressor icDx_{32, 2}, icDy_{32, 22}, icZ_{32, 20};
};

// GPS time (double, coded as a 64-bit integer): deltas predicted as multiples of the last
// delta, with up to four sequences to jump between (interleaved flight lines).
class GpsTime11Decoder {
   public:
    static constexpr uint32_t kMulti = 500;
    static constexpr int32_t kMultiMinus = -10;
    static constexpr uint32_t kMultiUnchanged = kMulti - kMultiMinus + 1;  // 511
    static constexpr uint32_t kMultiCodeFull = kMulti - kMultiMinus + 2;   // 512
    static constexpr uint32_t kMultiTotal = kMulti - kMultiMinus + 6;      // 516

    void init(const uint8_t* raw) { time_[0] = loadU64(raw); }

    void read(ArithmeticDecoder& dec, uint8_t* out) {
        // at most one switch of sequence per point in a valid stream; a loop (not
        // recursion) bounds a corrupt one
        for (int guard = 0; guard < 8; ++guard) {
            if (diff_[last_] == 0) {
                const uint32_t multi = dec.decodeSymbol(zeroDiff_);
                if (multi == 1) {
                    diff_[last_] = ic_.decompress(dec, 0, 0);
                    time_[last_] += uint64_t(int64_t(diff_[last_]));
                    extreme_[last_] = 0;
                } else if (multi == 2) {
                    readFull(dec);
                } else if (multi > 2) {
                    last_ = (last_ + multi - 2) & 3;
                    continue;
                }
            } else {
                const uint32_t multi = dec.decodeSymbol(multi_);
                if (multi == 1) {
                    time_[last_] += uint64_t(int64_t(ic_.decompress(dec, diff_[last_], 1)));
                    extreme_[last_] = 0;
                } else if (multi < kMultiUnchanged) {
                    int32_t d;
                    if (multi == 0) {
                        d = ic_.decompress(dec, 0, 7);
                        extreme(d);
                    } else if (multi < kMulti) {
                        d = ic_.decompress(dec, int32_t(multi * uint32_t(diff_[last_])), multi < 10 ? 2 : 3);
                    } else if (multi == kMulti) {
                        d = ic_.decompress(dec, int32_t(multi * uint32_t(diff_[last_])), 4);
                        extreme(d);
                    } else {
                        const int32_t mm = int32_t(kMulti) - int32_t(multi);
                        if (mm > kMultiMinus) {
                            d = ic_.decompress(dec, int32_t(uint32_t(mm) * uint32_t(diff_[last_])), 5);
                        } else {
                            d = ic_.decompress(dec, int32_t(uint32_t(kMultiMinus) * uint32_t(diff_[last_])), 6);
                            extreme(d);
                        }
                    }
                    time_[last_] += uint64_t(int64_t(d));
                } else if (multi == kMultiCodeFull) {
                    readFull(dec);
                } else if (multi > kMultiCodeFull) {
                    last_ = (last_ + multi - kMultiCodeFull) & 3;
                    continue;
                }
            }
            break;
        }
        std::memcpy(out, &time_[last_], 8);
    }

   private:
    void extreme(int32_t d) {
        if (++extreme_[last_] > 3) {
            diff_[last_] = d;
            extreme_[last_] = 0;
        }
    }
    void readFull(ArithmeticDecoder& dec) {
        next_ = (next_ + 1) & 3;
        const uint32_t high = uint32_t(ic_.decompress(dec, int32_t(uint32_t(time_[last_] >> 32)), 8));
        time_[next_] = (uint64_t(high) << 32) | dec.readInt();
        last_ = next_;
        diff_[last_] = 0;
        extreme_[last_] = 0;
    }

    uint32_t last_ = 0, next_ = 0;
    uint64_t time_[4] = {};
    int32_t diff_[4] = {};
    int32_t extreme_[4] = {};
    SymbolModel multi_{kMultiTotal}, zeroDiff_{6};
    IntegerDecompressor ic_{32, 9};
};

// RGB: low and high bytes of each channel separately; differences of red predict green
// and blue.
class Rgb12Decoder {
   public:
    void init(const uint8_t* raw) {
        for (int c = 0; c < 3; ++c) last_[c] = loadU16(raw + 2 * c);
    }

    void read(ArithmeticDecoder& dec, uint8_t* out) {
        uint16_t v[3];
        const uint32_t sym = dec.decodeSymbol(byteUsed_);
        v[0] = (sym & 1) ? foldByte(int32_t(dec.decodeSymbol(diff_[0])) + (last_[0] & 255)) : (last_[0] & 255);
        v[0] |= (sym & 2) ? uint16_t(foldByte(int32_t(dec.decodeSymbol(diff_[1])) + (last_[0] >> 8)) << 8)
                          : (last_[0] & 0xFF00);
        if (sym & 64) {
            int32_t d = int32_t(v[0] & 255) - int32_t(last_[0] & 255);
            v[1] = (sym & 4) ? foldByte(int32_t(dec.decodeSymbol(diff_[2])) + clampByte(d + (last_[1] & 255)))
                             : (last_[1] & 255);
            if (sym & 16) {
                d = (d + int32_t(v[1] & 255) - int32_t(last_[1] & 255)) / 2;
                v[2] = foldByte(int32_t(dec.decodeSymbol(diff_[4])) + clampByte(d + (last_[2] & 255)));
            } else {
                v[2] = last_[2] & 255;
            }
            d = int32_t(v[0] >> 8) - int32_t(last_[0] >> 8);
            v[1] |= (sym & 8)
                        ? uint16_t(foldByte(int32_t(dec.decodeSymbol(diff_[3])) + clampByte(d + (last_[1] >> 8))) << 8)
                        : (last_[1] & 0xFF00);
            if (sym & 32) {
                d = (d + int32_t(v[1] >> 8) - int32_t(last_[1] >> 8)) / 2;
                v[2] |= uint16_t(foldByte(int32_t(dec.decodeSymbol(diff_[5])) + clampByte(d + (last_[2] >> 8))) << 8);
            } else {
                v[2] |= last_[2] & 0xFF00;
            }
        } else {
            v[1] = v[2] = v[0];
        }
        std::memcpy(last_, v, 6);
        std::memcpy(out, v, 6);
    }

   private:
    uint16_t last_[3] = {};
    SymbolModel byteUsed_{128};
    SymbolModel diff_[6] = {SymbolModel(256), SymbolModel(256), SymbolModel(256),
                            SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};

// Extra bytes: each byte's difference to the previous point's, one model per byte.
class ByteDecoder {
   public:
    explicit ByteDecoder(uint32_t n) : last_(n) {
        models_.reserve(n);
        for (uint32_t i = 0; i < n; ++i) models_.emplace_back(256);
    }
    void init(const uint8_t* raw) { std::memcpy(last_.data(), raw, last_.size()); }
    void read(ArithmeticDecoder& dec, uint8_t* out) {
        for (size_t i = 0; i < last_.size(); ++i) last_[i] = uint8_t(last_[i] + dec.decodeSymbol(models_[i]));
        std::memcpy(out, last_.data(), last_.size());
    }

   private:
    std::vector<uint8_t> last_;
    std::vector<SymbolModel> models_;
};

}  // namespace

void decodePointwiseChunk(const LazInfo& info, std::span<const uint8_t> bytes, uint64_t points, uint8_t* out,
                          const std::string& source, uint64_t chunk) {
    const uint32_t recordLength = info.recordLength();
    if (points == 0) return;
    if (bytes.size() < recordLength)
        throw Error(source, "LAZ chunk " + std::to_string(chunk) + ": " + std::to_string(bytes.size()) +
                                " bytes, less than its first (raw) point");
    // The layout is fixed per file: the common ones get a loop without dispatch.
    Point10Decoder point;
    std::unique_ptr<GpsTime11Decoder> gps;
    std::unique_ptr<Rgb12Decoder> rgb;
    std::vector<std::pair<uint32_t, ByteDecoder>> extra;  // offset in the record, decoder
    uint32_t gpsAt = 0, rgbAt = 0, offset = 0;
    for (const Item& it : info.items) {
        switch (it.type) {
            case kPoint10:
                break;
            case kGpsTime11:
                gps = std::make_unique<GpsTime11Decoder>();
                gpsAt = offset;
                break;
            case kRgb12:
                rgb = std::make_unique<Rgb12Decoder>();
                rgbAt = offset;
                break;
            case kByte:
                extra.emplace_back(offset, ByteDecoder(it.size));
                break;
            default:
                break;  // checkItems rejected the rest
        }
        offset += it.size;
    }
    std::memcpy(out, bytes.data(), recordLength);
    point.init(out);
    if (gps) gps->init(out + gpsAt);
    if (rgb) rgb->init(out + rgbAt);
    for (auto& [at, d] : extra) d.init(out + at);

    ArithmeticDecoder dec(bytes.subspan(recordLength));
    uint8_t* rec = out + recordLength;
    for (uint64_t i = 1; i < points; ++i, rec += recordLength) {
        point.read(dec, rec);
        if (gps) gps->read(dec, rec + gpsAt);
        if (rgb) rgb->read(dec, rec + rgbAt);
        for (auto& [at, d] : extra) d.read(dec, rec + at);
        if (dec.overrun() > 8) [[unlikely]]
            throw Error(source, "LAZ chunk " + std::to_string(chunk) + ": truncated or corrupt (its " +
                                    std::to_string(bytes.size()) + " bytes end at point " + std::to_string(i) + " of " +
                                    std::to_string(points) + ")");
    }
}

}  // namespace rtfact::points::laz
