// Sequential bytes from a file at an offset, raw or zlib/gzip compressed. A compressed
// stream is only complete once zlib has seen its end and checked its trailer (CRC-32 and
// length for gzip, Adler-32 for zlib): finish() decodes up to there, so a stream cut after
// the bytes a header asks for is an error rather than a silent success.
#pragma once
#include <zlib.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace rtfact::io {

class ByteStream {
   public:
    // Throws Error(path, ...) when the file is not a regular file or cannot be opened.
    ByteStream(const std::string& path, uint64_t offset, bool compressed);
    ~ByteStream();
    ByteStream(const ByteStream&) = delete;
    ByteStream& operator=(const ByteStream&) = delete;

    // Reads exactly n bytes or throws naming what was being read.
    void read(void* dst, size_t n, const char* what);
    void skip(uint64_t n, const char* what);
    // Compressed: decodes (and drops) the rest of the stream, checking every member's
    // trailer; throws when the file ends inside a member or the trailer does not match.
    void finish();

   private:
    size_t readSome(uint8_t* dst, size_t n);
    void step();
    std::string format() const { return gzip_ ? "gzip" : "zlib"; }
    std::string trailer() const { return gzip_ ? "CRC-32/length" : "Adler-32"; }

    std::string path_;
    bool compressed_;
    FILE* f_ = nullptr;
    z_stream z_{};
    bool zinit_ = false;
    bool inMember_ = false, ended_ = false, padding_ = false, gzip_ = true;
    int members_ = 0;
    uint8_t in_[1 << 16];
};

}  // namespace rtfact::io
