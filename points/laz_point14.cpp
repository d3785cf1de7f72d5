// Compressor 3 items, version 3 (POINT14, RGB14, RGBNIR14, WAVEPACKET14, BYTE14). The XY layer carries,
// per point, which of scanner channel, point source, GPS time, scan angle, number of
// returns and return number changed; the other layers decode only what changed, each with
// predictions from the previous point of the same scanner channel.
#include "points/laz_point14.h"

#include <array>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "core/util/error.h"
#include "points/laz_arithmetic_decoder.h"
#include "points/laz_items.h"

namespace rtfact::points::laz {

namespace {

// [number of returns][return number] -> one of 6 return-map contexts / 8 return levels.
constexpr uint8_t kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
constexpr uint8_t kReturnLevel8[16][16] = {
    {0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7, 7, 7}, {1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7, 7},
    {2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7, 7}, {3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7, 7},
    {4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7, 7}, {5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7, 7},
    {6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7, 7}, {7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7, 7},
    {7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6, 7}, {7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5, 6},
    {7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4, 5}, {7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3, 4},
    {7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2, 3}, {7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1, 2},
    {7, 7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0, 1}, {7, 7, 7, 7, 7, 7, 7, 7, 7, 6, 5, 4, 3, 2, 1, 0}};

// One layer: its arithmetic stream, or none when the layer has no bytes (the field then
// repeats the previous point's value for the whole chunk).
struct Layer {
    ArithmeticDecoder dec;
    bool present = false;
    uint64_t bytes = 0;
};

// The LAS 1.4 core point, unpacked.
struct Point14 {
    int32_t x = 0, y = 0, z = 0;
    uint16_t intensity = 0;
    uint8_t r = 0, n = 0;  // return number, number of returns (4 bits each)
    uint8_t classFlags = 0, channel = 0, scanDir = 0, edge = 0;
    uint8_t classification = 0, userData = 0;
    int16_t scanAngle = 0;
    uint16_t sourceId = 0;
    uint64_t gpsTime = 0;  // the double's bits
    bool gpsTimeChange = false;

    void load(const uint8_t* p) {
        x = int32_t(loadU32(p));
        y = int32_t(loadU32(p + 4));
        z = int32_t(loadU32(p + 8));
        intensity = loadU16(p + 12);
        r = p[14] & 15;
        n = p[14] >> 4;
        classFlags = p[15] & 15;
        channel = (p[15] >> 4) & 3;
        scanDir = (p[15] >> 6) & 1;
        edge = p[15] >> 7;
        classification = p[16];
        userData = p[17];
        scanAngle = int16_t(loadU16(p + 18));
        sourceId = loadU16(p + 20);
        gpsTime = loadU64(p + 22);
    }
    void store(uint8_t* p) const {
        std::memcpy(p, &x, 4);
        std::memcpy(p + 4, &y, 4);
        std::memcpy(p + 8, &z, 4);
        std::memcpy(p + 12, &intensity, 2);
        p[14] = uint8_t(r | (n << 4));
        p[15] = uint8_t(classFlags | (channel << 4) | (scanDir << 6) | (edge << 7));
        p[16] = classification;
        p[17] = userData;
        std::memcpy(p + 18, &scanAngle, 2);
        std::memcpy(p + 20, &sourceId, 2);
        std::memcpy(p + 22, &gpsTime, 8);
    }
};

// GPS time, layered variant: the "changed" bit already says the time differs, so the
// symbols have no "unchanged" code.
struct GpsTime14 {
    static constexpr uint32_t kMulti = 500;
    static constexpr int32_t kMultiMinus = -10;
    static constexpr uint32_t kMultiCodeFull = kMulti - kMultiMinus + 1;  // 511
    static constexpr uint32_t kMultiTotal = kMulti - kMultiMinus + 5;     // 515

    uint32_t last = 0, next = 0;
    uint64_t time[4] = {};
    int32_t diff[4] = {};
    int32_t extremeCount[4] = {};
    SymbolModel multi{kMultiTotal}, zeroDiff{5};
    IntegerDecompressor ic{32, 9};

    explicit GpsTime14(uint64_t t) { time[0] = t; }

    uint64_t read(ArithmeticDecoder& dec) {
        for (int guard = 0; guard < 8; ++guard) {  // bounded: a corrupt stream cannot recurse forever
            if (diff[last] == 0) {
                const uint32_t m = dec.decodeSymbol(zeroDiff);
                if (m == 0) {
                    diff[last] = ic.decompress(dec, 0, 0);
                    time[last] += uint64_t(int64_t(diff[last]));
                    extremeCount[last] = 0;
                } else if (m == 1) {
                    readFull(dec);
                } else {
                    last = (last + m - 1) & 3;
                    continue;
                }
            } else {
                const uint32_t m = dec.decodeSymbol(multi);
                if (m == 1) {
                    time[last] += uint64_t(int64_t(ic.decompress(dec, diff[last], 1)));
                    extremeCount[last] = 0;
                } else if (m < kMultiCodeFull) {
                    int32_t d;
                    if (m == 0) {
                        d = ic.decompress(dec, 0, 7);
                        extreme(d);
                    } else if (m < kMulti) {
                        d = ic.decompress(dec, int32_t(m * uint32_t(diff[last])), m < 10 ? 2 : 3);
                    } else if (m == kMulti) {
                        d = ic.decompress(dec, int32_t(m * uint32_t(diff[last])), 4);
                        extreme(d);
                    } else {
                        const int32_t mm = int32_t(kMulti) - int32_t(m);
                        if (mm > kMultiMinus) {
                            d = ic.decompress(dec, int32_t(uint32_t(mm) * uint32_t(diff[last])), 5);
                        } else {
                            d = ic.decompress(dec, int32_t(uint32_t(kMultiMinus) * uint32_t(diff[last])), 6);
                            extreme(d);
                        }
                    }
                    time[last] += uint64_t(int64_t(d));
                } else if (m == kMultiCodeFull) {
                    readFull(dec);
                } else {
                    last = (last + m - kMultiCodeFull) & 3;
                    continue;
                }
            }
            break;
        }
        return time[last];
    }
    void extreme(int32_t d) {
        if (++extremeCount[last] > 3) {
            diff[last] = d;
            extremeCount[last] = 0;
        }
    }
    void readFull(ArithmeticDecoder& dec) {
        next = (next + 1) & 3;
        const uint32_t high = uint32_t(ic.decompress(dec, int32_t(uint32_t(time[last] >> 32)), 8));
        time[next] = (uint64_t(high) << 32) | dec.readInt();
        last = next;
        diff[last] = 0;
        extremeCount[last] = 0;
    }
};

// Everything predicted per scanner channel for the core point.
struct Point14Context {
    Point14 last;
    uint16_t lastIntensity[8];
    int32_t lastZ[8];
    StreamingMedian5 medianX[12], medianY[12];
    SymbolModel changedValues[8] = {SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128),
                                    SymbolModel(128), SymbolModel(128), SymbolModel(128), SymbolModel(128)};
    SymbolModel scannerChannel{3};
    LazySymbolModels numberOfReturns{16, 16}, returnNumber{16, 16};
    SymbolModel returnNumberGpsSame{13};
    IntegerDecompressor icDx{32, 2}, icDy{32, 22}, icZ{32, 20};
    LazySymbolModels classification{64, 256}, flags{64, 64}, userData{64, 256};
    IntegerDecompressor icIntensity{16, 4}, icScanAngle{16, 2}, icSourceId{16};
    GpsTime14 gps;

    explicit Point14Context(const Point14& p) : last(p), gps(p.gpsTime) {
        last.gpsTimeChange = false;
        for (auto& i : lastIntensity) i = p.intensity;
        for (auto& z : lastZ) z = p.z;
    }
};

enum : int { kXY, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kSource, kGps, kPointLayers };

class Point14Decoder {
   public:
    Layer layers[kPointLayers];

    void init(const uint8_t* raw, uint32_t& context) {
        Point14 p;
        p.load(raw);
        current_ = p.channel;
        contexts_[current_].emplace(p);
        context = current_;
    }

    void read(uint8_t* out, uint32_t& context) {
        Point14Context* c = &*contexts_[current_];
        Point14* last = &c->last;
        ArithmeticDecoder& xy = layers[kXY].dec;
        const uint32_t lpr = (last->r == 1 ? 1 : 0) + (last->r >= last->n ? 2 : 0) + (last->gpsTimeChange ? 4 : 0);
        const uint32_t changed = xy.decodeSymbol(c->changedValues[lpr]);
        if (changed & (1 << 6)) {
            const uint32_t diff = xy.decodeSymbol(c->scannerChannel);
            const uint32_t channel = (current_ + diff + 1) & 3;
            if (!contexts_[channel]) contexts_[channel].emplace(*last);
            current_ = channel;
            c = &*contexts_[current_];
            last = &c->last;
            last->channel = uint8_t(channel);
        }
        context = current_;
        const bool sourceChange = changed & (1 << 5);
        const bool gpsChange = changed & (1 << 4);
        const bool angleChange = changed & (1 << 3);

        uint32_t n = last->n, r = last->r;
        if (changed & (1 << 2)) {
            n = xy.decodeSymbol(c->numberOfReturns[n]);
            last->n = uint8_t(n);
        }
        switch (changed & 3) {
            case 1:
                r = (r + 1) & 15;
                break;
            case 2:
                r = (r + 15) & 15;
                break;
            case 3:
                if (gpsChange)
                    r = xy.decodeSymbol(c->returnNumber[r]);
                else
                    r = (r + xy.decodeSymbol(c->returnNumberGpsSame) + 2) & 15;
                break;
            default:
                break;
        }
        last->r = uint8_t(r);
        const uint32_t m = kReturnMap6[n][r], l = kReturnLevel8[n][r];
        const uint32_t cpr = (r == 1 ? 2 : 0) + (r >= n ? 1 : 0);
        const uint32_t mi = (m << 1) | (gpsChange ? 1 : 0);

        int32_t d = c->icDx.decompress(xy, c->medianX[mi].get(), n == 1);
        last->x = int32_t(uint32_t(last->x) + uint32_t(d));
        c->medianX[mi].add(d);
        uint32_t k = c->icDx.k();
        d = c->icDy.decompress(xy, c->medianY[mi].get(), (n == 1) + (k < 20 ? (k & ~1u) : 20));
        last->y = int32_t(uint32_t(last->y) + uint32_t(d));
        c->medianY[mi].add(d);

        if (layers[kZ].present) {
            k = (c->icDx.k() + c->icDy.k()) / 2;
            last->z = c->icZ.decompress(layers[kZ].dec, c->lastZ[l], (n == 1) + (k < 18 ? (k & ~1u) : 18));
            c->lastZ[l] = last->z;
        }
        if (layers[kClass].present) {
            const uint32_t ccc = ((last->classification & 0x1Fu) << 1) + (cpr == 3 ? 1 : 0);
            last->classification = uint8_t(layers[kClass].dec.decodeSymbol(c->classification[ccc]));
        }
        if (layers[kFlags].present) {
            const uint32_t lastFlags = (uint32_t(last->edge) << 5) | (uint32_t(last->scanDir) << 4) | last->classFlags;
            const uint32_t f = layers[kFlags].dec.decodeSymbol(c->flags[lastFlags]);
            last->edge = (f >> 5) & 1;
            last->scanDir = (f >> 4) & 1;
            last->classFlags = f & 15;
        }
        if (layers[kIntensity].present) {
            const uint32_t at = (cpr << 1) | (gpsChange ? 1 : 0);
            last->intensity = uint16_t(c->icIntensity.decompress(layers[kIntensity].dec, c->lastIntensity[at], cpr));
            c->lastIntensity[at] = last->intensity;
        }
        if (layers[kScanAngle].present && angleChange)
            last->scanAngle =
                int16_t(c->icScanAngle.decompress(layers[kScanAngle].dec, last->scanAngle, gpsChange ? 1 : 0));
        if (layers[kUserData].present)
            last->userData = uint8_t(layers[kUserData].dec.decodeSymbol(c->userData[last->userData / 4]));
        if (layers[kSource].present && sourceChange)
            last->sourceId = uint16_t(c->icSourceId.decompress(layers[kSource].dec, last->sourceId));
        if (layers[kGps].present && gpsChange) last->gpsTime = c->gps.read(layers[kGps].dec);
        last->store(out);
        last->gpsTimeChange = gpsChange;
    }

   private:
    uint32_t current_ = 0;
    std::optional<Point14Context> contexts_[4];
};

// RGB (and NIR) per scanner channel: the same byte-wise coding as RGB12.
struct RgbContext {
    uint16_t last[4] = {};
    SymbolModel rgbUsed{128};
    SymbolModel rgbDiff[6] = {SymbolModel(256), SymbolModel(256), SymbolModel(256),
                              SymbolModel(256), SymbolModel(256), SymbolModel(256)};
    SymbolModel nirUsed{4};
    SymbolModel nirDiff[2] = {SymbolModel(256), SymbolModel(256)};
    explicit RgbContext(const uint16_t* from) { std::memcpy(last, from, sizeof last); }
};

class RgbNir14Decoder {
   public:
    Layer rgb, nir;
    explicit RgbNir14Decoder(bool withNir) : nirItem_(withNir) {}

    void init(const uint8_t* raw, uint32_t context) {
        uint16_t v[4] = {};
        std::memcpy(v, raw, nirItem_ ? 8 : 6);
        current_ = context;
        contexts_[current_].emplace(v);
    }

    void read(uint8_t* out, uint32_t context) {
        if (context != current_) {
            if (!contexts_[context]) contexts_[context].emplace(contexts_[current_]->last);
            current_ = context;
        }
        RgbContext& c = *contexts_[current_];
        uint16_t* last = c.last;
        if (rgb.present) {
            ArithmeticDecoder& dec = rgb.dec;
            uint16_t v[3];
            const uint32_t sym = dec.decodeSymbol(c.rgbUsed);
            v[0] = (sym & 1) ? foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[0])) + (last[0] & 255)) : (last[0] & 255);
            v[0] |= (sym & 2) ? uint16_t(foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[1])) + (last[0] >> 8)) << 8)
                              : (last[0] & 0xFF00);
            if (sym & 64) {
                int32_t d = int32_t(v[0] & 255) - int32_t(last[0] & 255);
                v[1] = (sym & 4) ? foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[2])) + clampByte(d + (last[1] & 255)))
                                 : (last[1] & 255);
                if (sym & 16) {
                    d = (d + int32_t(v[1] & 255) - int32_t(last[1] & 255)) / 2;
                    v[2] = foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[4])) + clampByte(d + (last[2] & 255)));
                } else {
                    v[2] = last[2] & 255;
                }
                d = int32_t(v[0] >> 8) - int32_t(last[0] >> 8);
                v[1] |= (sym & 8)
                            ? uint16_t(foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[3])) + clampByte(d + (last[1] >> 8)))
                                       << 8)
                            : (last[1] & 0xFF00);
                if (sym & 32) {
                    d = (d + int32_t(v[1] >> 8) - int32_t(last[1] >> 8)) / 2;
                    v[2] |= uint16_t(foldByte(int32_t(dec.decodeSymbol(c.rgbDiff[5])) + clampByte(d + (last[2] >> 8)))
                                     << 8);
                } else {
                    v[2] |= last[2] & 0xFF00;
                }
            } else {
                v[1] = v[2] = v[0];
            }
            std::memcpy(last, v, 6);
        }
        if (nirItem_ && nir.present) {
            ArithmeticDecoder& dec = nir.dec;
            const uint32_t sym = dec.decodeSymbol(c.nirUsed);
            uint16_t v =
                (sym & 1) ? foldByte(int32_t(dec.decodeSymbol(c.nirDiff[0])) + (last[3] & 255)) : (last[3] & 255);
            v |= (sym & 2) ? uint16_t(foldByte(int32_t(dec.decodeSymbol(c.nirDiff[1])) + (last[3] >> 8)) << 8)
                           : (last[3] & 0xFF00);
            last[3] = v;
        }
        std::memcpy(out, last, nirItem_ ? 8 : 6);
    }

   private:
    bool nirItem_;
    uint32_t current_ = 0;
    std::optional<RgbContext> contexts_[4];
};

// Extra bytes, one layer per byte, per scanner channel.
class Byte14Decoder {
   public:
    std::vector<Layer> layers;
    explicit Byte14Decoder(uint32_t n) : layers(n), n_(n) {}

    void init(const uint8_t* raw, uint32_t context) {
        current_ = context;
        contexts_[current_] = std::make_unique<Context>(raw, n_);
    }
    void read(uint8_t* out, uint32_t context) {
        if (context != current_) {
            if (!contexts_[context])
                contexts_[context] = std::make_unique<Context>(contexts_[current_]->last.data(), n_);
            current_ = context;
        }
        Context& c = *contexts_[current_];
        for (uint32_t i = 0; i < n_; ++i)
            if (layers[i].present) c.last[i] = uint8_t(c.last[i] + layers[i].dec.decodeSymbol(c.models[i]));
        std::memcpy(out, c.last.data(), n_);
    }

   private:
    struct Context {
        std::vector<uint8_t> last;
        std::vector<SymbolModel> models;
        Context(const uint8_t* from, uint32_t n) : last(from, from + n) {
            models.reserve(n);
            for (uint32_t i = 0; i < n; ++i) models.emplace_back(256);
        }
    };
    uint32_t n_;
    uint32_t current_ = 0;
    std::unique_ptr<Context> contexts_[4];
};

// Wave packet (descriptor index, byte offset, packet size, return point location and the
// x(t), y(t), z(t) parameters, floats coded as their 32-bit patterns), per scanner channel.
class WavePacket14Decoder {
   public:
    Layer layer;

    void init(const uint8_t* raw, uint32_t context) {
        current_ = context;
        contexts_[current_] = std::make_unique<Context>(raw);
    }
    void read(uint8_t* out, uint32_t context) {
        if (context != current_) {
            if (!contexts_[context]) contexts_[context] = std::make_unique<Context>(contexts_[current_]->last);
            current_ = context;
        }
        Context& c = *contexts_[current_];
        if (layer.present) {
            ArithmeticDecoder& dec = layer.dec;
            uint8_t v[29];
            v[0] = uint8_t(dec.decodeSymbol(c.packetIndex));
            const uint64_t lastOffset = loadU64(c.last + 1);
            const uint32_t lastSize = loadU32(c.last + 9);
            c.lastOffsetSym = dec.decodeSymbol(c.offsetDiff[c.lastOffsetSym]);
            uint64_t offset;
            switch (c.lastOffsetSym) {
                case 0:
                    offset = lastOffset;
                    break;
                case 1:
                    offset = lastOffset + lastSize;
                    break;
                case 2:
                    c.lastDiff32 = c.icOffsetDiff.decompress(dec, c.lastDiff32);
                    offset = lastOffset + uint64_t(int64_t(c.lastDiff32));
                    break;
                default: {
                    const uint64_t lower = dec.readInt();
                    offset = (uint64_t(dec.readInt()) << 32) | lower;
                }
            }
            std::memcpy(v + 1, &offset, 8);
            const int32_t size = c.icPacketSize.decompress(dec, int32_t(lastSize));
            std::memcpy(v + 9, &size, 4);
            const int32_t location = c.icReturnPoint.decompress(dec, int32_t(loadU32(c.last + 13)));
            std::memcpy(v + 13, &location, 4);
            for (uint32_t a = 0; a < 3; ++a) {
                const int32_t x = c.icXyz.decompress(dec, int32_t(loadU32(c.last + 17 + 4 * a)), a);
                std::memcpy(v + 17 + 4 * a, &x, 4);
            }
            std::memcpy(c.last, v, 29);
        }
        std::memcpy(out, c.last, 29);
    }

   private:
    struct Context {
        uint8_t last[29];
        int32_t lastDiff32 = 0;
        uint32_t lastOffsetSym = 0;
        SymbolModel packetIndex{256};
        SymbolModel offsetDiff[4] = {SymbolModel(4), SymbolModel(4), SymbolModel(4), SymbolModel(4)};
        IntegerDecompressor icOffsetDiff{32}, icPacketSize{32}, icReturnPoint{32}, icXyz{32, 3};
        explicit Context(const uint8_t* from) { std::memcpy(last, from, 29); }
    };
    uint32_t current_ = 0;
    std::unique_ptr<Context> contexts_[4];
};

}  // namespace

void decodeLayeredChunk(const LazInfo& info, std::span<const uint8_t> bytes, uint64_t points, uint8_t* out,
                        const std::string& source, uint64_t chunk) {
    auto fail = [&](const std::string& what) {
        throw Error(source, "LAZ chunk " + std::to_string(chunk) + ": " + what);
    };
    const uint32_t recordLength = info.recordLength();
    if (points == 0) return;
    if (bytes.size() < uint64_t(recordLength) + 4)
        fail(std::to_string(bytes.size()) + " bytes, too short for its first point");
    std::memcpy(out, bytes.data(), recordLength);
    size_t pos = recordLength;
    const uint32_t count = loadU32(bytes.data() + pos);
    pos += 4;
    if (count != points)
        fail("says it holds " + std::to_string(count) + " points, the chunk table " + std::to_string(points));

    Point14Decoder point;
    std::unique_ptr<RgbNir14Decoder> rgb;
    std::unique_ptr<Byte14Decoder> extra;
    std::unique_ptr<WavePacket14Decoder> wave;
    uint32_t rgbAt = 0, extraAt = 0, waveAt = 0, offset = 0;
    std::vector<Layer*> layers;  // in the order of their sizes and bytes
    for (const Item& it : info.items) {
        switch (it.type) {
            case kPoint14:
                for (Layer& l : point.layers) layers.push_back(&l);
                break;
            case kRgb14:
            case kRgbNir14:
                rgb = std::make_unique<RgbNir14Decoder>(it.type == kRgbNir14);
                rgbAt = offset;
                layers.push_back(&rgb->rgb);
                if (it.type == kRgbNir14) layers.push_back(&rgb->nir);
                break;
            case kWavePacket14:
                wave = std::make_unique<WavePacket14Decoder>();
                waveAt = offset;
                layers.push_back(&wave->layer);
                break;
            case kByte14:
                extra = std::make_unique<Byte14Decoder>(it.size);
                extraAt = offset;
                for (Layer& l : extra->layers) layers.push_back(&l);
                break;
            default:
                break;  // checkItems rejected the rest
        }
        offset += it.size;
    }
    if (bytes.size() - pos < 4 * layers.size())
        fail("too short for its " + std::to_string(layers.size()) + " layer sizes");
    for (Layer* l : layers) {
        l->bytes = loadU32(bytes.data() + pos);
        pos += 4;
    }
    for (size_t i = 0; i < layers.size(); ++i) {
        Layer* l = layers[i];
        if (l->bytes > bytes.size() - pos)
            fail("layer " + std::to_string(i) + " (" + std::to_string(l->bytes) + " bytes) runs past its end");
        l->present = l->bytes > 0;
        if (l->present) l->dec.init(bytes.subspan(pos, l->bytes));
        pos += l->bytes;
    }
    if (points > 1 && !point.layers[kXY].present) fail("no XY layer for " + std::to_string(points) + " points");

    uint32_t context = 0;
    point.init(out, context);
    if (rgb) rgb->init(out + rgbAt, context);
    if (wave) wave->init(out + waveAt, context);
    if (extra) extra->init(out + extraAt, context);
    uint8_t* rec = out + recordLength;
    for (uint64_t i = 1; i < points; ++i, rec += recordLength) {
        point.read(rec, context);
        if (rgb) rgb->read(rec + rgbAt, context);
        if (wave) wave->read(rec + waveAt, context);
        if (extra) extra->read(rec + extraAt, context);
        if (point.layers[kXY].dec.overrun() > 8) [[unlikely]]
            fail("truncated or corrupt (its XY layer ends at point " + std::to_string(i) + " of " +
                 std::to_string(points) + ")");
    }
    for (size_t i = 0; i < layers.size(); ++i)
        if (layers[i]->present && layers[i]->dec.overrun() > 8)
            fail("layer " + std::to_string(i) + " is truncated or corrupt");
}

}  // namespace rtfact::points::laz
