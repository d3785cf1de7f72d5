// LAZ entropy decoding: the adaptive range decoder LASzip uses (a 32-bit multi-symbol
// arithmetic coder after Amir Said's "FastAC"), its adaptive bit and symbol models, and the
// integer decompressor that turns "number of bits k + k-bit corrector" symbols back into
// differences from a prediction. All of it is written from the LAZ specification; the
// constants (length shifts, update cycles, table sizes) are part of the format: the encoder
// adapts its models in exactly this way, so the decoder must too.
//
// Hostile input: the decoder reads its bytes from a span and returns zeros past its end
// (counting them, so the caller can reject a chunk that ran past its bytes); every table
// index stays in range whatever the bytes are.
#pragma once
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <vector>

namespace rtfact::points::laz {

inline constexpr uint32_t kMinLength = 0x01000000u;  // renormalise below this
inline constexpr uint32_t kMaxLength = 0xFFFFFFFFu;
inline constexpr uint32_t kBitLengthShift = 13;  // bit models: probabilities of 13 bits
inline constexpr uint32_t kBitMaxCount = 1u << kBitLengthShift;
inline constexpr uint32_t kSymLengthShift = 15;  // symbol models: distributions of 15 bits
inline constexpr uint32_t kSymMaxCount = 1u << kSymLengthShift;

// Adaptive probability of a 0 bit.
struct BitModel {
    uint32_t bit0Prob = 1u << (kBitLengthShift - 1), bit0Count = 1, bitCount = 2;
    uint32_t updateCycle = 4, bitsUntilUpdate = 4;

    [[gnu::noinline]] void update() {
        if ((bitCount += updateCycle) > kBitMaxCount) {
            bitCount = (bitCount + 1) >> 1;
            bit0Count = (bit0Count + 1) >> 1;
            if (bit0Count == bitCount) ++bitCount;
        }
        const uint32_t scale = 0x80000000u / bitCount;
        bit0Prob = (bit0Count * scale) >> (31 - kBitLengthShift);
        updateCycle = (5 * updateCycle) >> 2;
        if (updateCycle > 64) updateCycle = 64;
        bitsUntilUpdate = updateCycle;
    }
};

// Adaptive distribution over `symbols` symbols; above 16 symbols a lookup table narrows the
// search for the decoded symbol.
class SymbolModel {
   public:
    explicit SymbolModel(uint32_t symbols) : symbols_(symbols), lastSymbol_(symbols - 1) {
        if (symbols > 16) {
            uint32_t tableBits = 3;
            while (symbols > (1u << (tableBits + 2))) ++tableBits;
            tableSize_ = 1u << tableBits;
            tableShift_ = kSymLengthShift - tableBits;
        }
        // distribution | counts | decoder table (tableSize + 2 entries)
        storage_.assign(2 * size_t(symbols) + (tableSize_ ? tableSize_ + 2 : 0), 0);
        distribution_ = storage_.data();
        counts_ = distribution_ + symbols;
        table_ = tableSize_ ? counts_ + symbols : nullptr;
        for (uint32_t k = 0; k < symbols; ++k) counts_[k] = 1;
        updateCycle_ = symbols;
        update();
        symbolsUntilUpdate_ = updateCycle_ = (symbols + 6) >> 1;
    }
    // Movable (the pointers follow the moved buffer), never copied (they would not).
    SymbolModel(SymbolModel&&) noexcept = default;
    SymbolModel& operator=(SymbolModel&&) noexcept = default;
    SymbolModel(const SymbolModel&) = delete;
    SymbolModel& operator=(const SymbolModel&) = delete;

    [[gnu::noinline]] void update() {
        if ((totalCount_ += updateCycle_) > kSymMaxCount) {
            totalCount_ = 0;
            for (uint32_t k = 0; k < symbols_; ++k) totalCount_ += (counts_[k] = (counts_[k] + 1) >> 1);
        }
        const uint32_t scale = 0x80000000u / totalCount_;
        uint32_t sum = 0;
        if (!tableSize_) {
            for (uint32_t k = 0; k < symbols_; ++k) {
                distribution_[k] = (scale * sum) >> (31 - kSymLengthShift);
                sum += counts_[k];
            }
        } else {
            uint32_t s = 0;
            for (uint32_t k = 0; k < symbols_; ++k) {
                distribution_[k] = (scale * sum) >> (31 - kSymLengthShift);
                sum += counts_[k];
                const uint32_t w = distribution_[k] >> tableShift_;
                while (s < w) table_[++s] = k - 1;
            }
            table_[0] = 0;
            while (s <= tableSize_) table_[++s] = symbols_ - 1;
        }
        updateCycle_ = (5 * updateCycle_) >> 2;
        const uint32_t maxCycle = (symbols_ + 6) << 3;
        if (updateCycle_ > maxCycle) updateCycle_ = maxCycle;
        symbolsUntilUpdate_ = updateCycle_;
    }

   private:
    friend class ArithmeticDecoder;
    std::vector<uint32_t> storage_;
    uint32_t* distribution_ = nullptr;
    uint32_t* counts_ = nullptr;
    uint32_t* table_ = nullptr;
    uint32_t symbols_, lastSymbol_;
    uint32_t tableSize_ = 0, tableShift_ = 0;
    uint32_t totalCount_ = 0, updateCycle_ = 0, symbolsUntilUpdate_ = 0;
};

class ArithmeticDecoder {
   public:
    ArithmeticDecoder() = default;
    // Starts decoding `bytes` (reads the first 4).
    explicit ArithmeticDecoder(std::span<const uint8_t> bytes) { init(bytes); }

    void init(std::span<const uint8_t> bytes) {
        p_ = bytes.data();
        end_ = p_ + bytes.size();
        overrun_ = 0;
        length_ = kMaxLength;
        value_ = 0;
        for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | nextByte();
    }

    // Bytes asked for past the end of the span (0 for a well-formed stream, up to a few
    // for the decoder's lookahead at the very end).
    uint32_t overrun() const { return overrun_; }
    const uint8_t* position() const { return p_; }

    [[gnu::always_inline]] uint32_t decodeBit(BitModel& m) {
        const uint32_t x = m.bit0Prob * (length_ >> kBitLengthShift);
        uint32_t sym;
        if (value_ < x) {
            sym = 0;
            length_ = x;
            ++m.bit0Count;
        } else {
            sym = 1;
            value_ -= x;
            length_ -= x;
        }
        if (length_ < kMinLength) renormalise();
        if (--m.bitsUntilUpdate == 0) m.update();
        return sym;
    }

    [[gnu::always_inline]] uint32_t decodeSymbol(SymbolModel& m) {
        uint32_t sym, x, y = length_;
        if (m.table_) {
            length_ >>= kSymLengthShift;
            const uint32_t dv = value_ / length_;
            uint32_t t = dv >> m.tableShift_;
            if (t > m.tableSize_) t = m.tableSize_;  // only for a corrupt stream (value >= length)
            sym = m.table_[t];
            uint32_t n = m.table_[t + 1] + 1;
            while (n > sym + 1) {  // binary search within the table's bracket
                const uint32_t k = (sym + n) >> 1;
                if (m.distribution_[k] > dv)
                    n = k;
                else
                    sym = k;
            }
            x = m.distribution_[sym] * length_;
            if (sym != m.lastSymbol_) y = m.distribution_[sym + 1] * length_;
        } else {
            x = sym = 0;
            length_ >>= kSymLengthShift;
            uint32_t n = m.symbols_, k = n >> 1;
            do {  // bisection over the distribution
                const uint32_t z = length_ * m.distribution_[k];
                if (z > value_) {
                    n = k;
                    y = z;
                } else {
                    sym = k;
                    x = z;
                }
            } while ((k = (sym + n) >> 1) != sym);
        }
        value_ -= x;
        length_ = y - x;
        if (length_ < kMinLength) renormalise();
        ++m.counts_[sym];
        if (--m.symbolsUntilUpdate_ == 0) m.update();
        return sym;
    }

    // `bits` raw bits (1..32), sent without a model.
    uint32_t readBits(uint32_t bits) {
        if (bits > 19) {
            const uint32_t lower = readShort();
            return (readBits(bits - 16) << 16) | lower;
        }
        const uint32_t sym = value_ / (length_ >>= bits);
        value_ -= length_ * sym;
        if (length_ < kMinLength) renormalise();
        return sym;
    }
    uint32_t readShort() {
        const uint32_t sym = value_ / (length_ >>= 16);
        value_ -= length_ * sym;
        if (length_ < kMinLength) renormalise();
        return sym;
    }
    uint32_t readInt() {
        const uint32_t lower = readShort();
        return (readShort() << 16) | lower;
    }

   private:
    uint32_t nextByte() {
        if (p_ < end_) return *p_++;
        ++overrun_;
        return 0;
    }
    void renormalise() {
        do {
            value_ = (value_ << 8) | nextByte();
        } while ((length_ <<= 8) < kMinLength);
    }

    const uint8_t* p_ = nullptr;
    const uint8_t* end_ = nullptr;
    uint32_t value_ = 0, length_ = kMaxLength, overrun_ = 0;
};

// Integers sent as a correction to a prediction: first the number k of significant bits
// of the correction (one symbol model per context), then the correction itself (a bit for
// k = 0, a symbol of k bits up to `bitsHigh`, raw bits beyond).
class IntegerDecompressor {
   public:
    explicit IntegerDecompressor(uint32_t bits = 16, uint32_t contexts = 1, uint32_t bitsHigh = 8)
        : bits_(bits), bitsHigh_(bitsHigh) {
        if (bits < 32) {
            corrRange_ = 1u << bits;
            corrMin_ = -int32_t(corrRange_ / 2);
        } else {
            corrRange_ = 0;
            corrMin_ = INT32_MIN;
        }
        kModels_.reserve(contexts);
        correctors_.reserve(bits);
        for (uint32_t i = 0; i < contexts; ++i) kModels_.emplace_back(bits + 1);
        for (uint32_t i = 1; i <= bits; ++i) correctors_.emplace_back(i <= bitsHigh ? 1u << i : 1u << bitsHigh);
    }

    // The value `pred` + correction, wrapped into the integer range of `bits` bits.
    int32_t decompress(ArithmeticDecoder& dec, int32_t pred, uint32_t context = 0) {
        uint32_t real = uint32_t(pred) + uint32_t(readCorrector(dec, kModels_[context]));
        if (corrRange_) {
            if (int32_t(real) < 0)
                real += corrRange_;
            else if (real >= corrRange_)
                real -= corrRange_;
        }
        return int32_t(real);
    }
    // k of the last correction: later predictions use it as context.
    uint32_t k() const { return k_; }

   private:
    int32_t readCorrector(ArithmeticDecoder& dec, SymbolModel& kModel) {
        k_ = dec.decodeSymbol(kModel);
        if (k_ == 0) return int32_t(dec.decodeBit(bit0_));
        if (k_ >= 32) return corrMin_;
        uint32_t c;
        if (k_ <= bitsHigh_) {
            c = dec.decodeSymbol(correctors_[k_ - 1]);
        } else {
            const uint32_t k1 = k_ - bitsHigh_;
            c = dec.decodeSymbol(correctors_[k_ - 1]);
            c = (c << k1) | dec.readBits(k1);
        }
        // c in [0, 2^k) maps to [-(2^k - 1), -2^(k-1)] and [2^(k-1) + 1, 2^k]
        if (c >= (1u << (k_ - 1))) return int32_t(c + 1);
        return int32_t(c - ((1u << k_) - 1));
    }

    uint32_t bits_, bitsHigh_;
    uint32_t corrRange_;
    int32_t corrMin_;
    uint32_t k_ = 0;
    BitModel bit0_;
    std::vector<SymbolModel> kModels_, correctors_;
};

// A symbol model created on first use (LASzip allocates the large per-value context
// families lazily; creating them all per chunk would cost more than decoding small chunks).
class LazySymbolModels {
   public:
    LazySymbolModels(size_t count, uint32_t symbols) : models_(count), symbols_(symbols) {}
    SymbolModel& operator[](size_t i) {
        auto& m = models_[i];
        if (!m) m = std::make_unique<SymbolModel>(symbols_);
        return *m;
    }

   private:
    std::vector<std::unique_ptr<SymbolModel>> models_;
    uint32_t symbols_;
};

// The median of the last five values: LASzip's predictor of X and Y differences.
struct StreamingMedian5 {
    int32_t v[5] = {0, 0, 0, 0, 0};
    bool high = true;

    int32_t get() const { return v[2]; }
    void add(int32_t x) {
        if (high) {
            if (x < v[2]) {
                v[4] = v[3];
                v[3] = v[2];
                if (x < v[0]) {
                    v[2] = v[1];
                    v[1] = v[0];
                    v[0] = x;
                } else if (x < v[1]) {
                    v[2] = v[1];
                    v[1] = x;
                } else {
                    v[2] = x;
                }
            } else {
                if (x < v[3]) {
                    v[4] = v[3];
                    v[3] = x;
                } else {
                    v[4] = x;
                }
                high = false;
            }
        } else {
            if (v[2] < x) {
                v[0] = v[1];
                v[1] = v[2];
                if (v[4] < x) {
                    v[2] = v[3];
                    v[3] = v[4];
                    v[4] = x;
                } else if (v[3] < x) {
                    v[2] = v[3];
                    v[3] = x;
                } else {
                    v[2] = x;
                }
            } else {
                if (v[1] < x) {
                    v[0] = v[1];
                    v[1] = x;
                } else {
                    v[0] = x;
                }
                high = true;
            }
        }
    }
};

inline uint8_t foldByte(int32_t n) { return uint8_t(n); }  // modulo 256
inline int32_t clampByte(int32_t n) { return n < 0 ? 0 : (n > 255 ? 255 : n); }

inline uint16_t loadU16(const uint8_t* p) {
    uint16_t v;
    std::memcpy(&v, p, 2);
    return v;
}
inline uint32_t loadU32(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v;
}
inline uint64_t loadU64(const uint8_t* p) {
    uint64_t v;
    std::memcpy(&v, p, 8);
    return v;
}

}  // namespace rtfact::points::laz
