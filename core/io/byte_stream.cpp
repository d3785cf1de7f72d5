#include "core/io/byte_stream.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "core/util/error.h"
#include "core/util/input_file.h"

namespace rtfact::io {

ByteStream::ByteStream(const std::string& path, uint64_t offset, bool compressed)
    : path_(path), compressed_(compressed) {
    requireRegularFile(path);  // a FIFO would block fopen
    f_ = std::fopen(path.c_str(), "rb");
    if (!f_) throw Error(path, "cannot open file");
    // The destructor does not run when the constructor throws: close the file here.
    auto fail = [&](const char* what) {
        std::fclose(f_);
        return Error(path, what);
    };
    if (fseeko(f_, off_t(offset), SEEK_SET) != 0) throw fail("cannot seek to the data");
    if (compressed_) {
        std::memset(&z_, 0, sizeof(z_));
        if (inflateInit2(&z_, 15 + 32) != Z_OK) throw fail("cannot initialise zlib");
        zinit_ = true;
    }
}
ByteStream::~ByteStream() {
    if (zinit_) inflateEnd(&z_);
    if (f_) std::fclose(f_);
}

void ByteStream::read(void* dst, size_t n, const char* what) {
    const size_t got = readSome(static_cast<uint8_t*>(dst), n);
    if (got != n)
        throw Error(path_, std::string("truncated ") + (compressed_ ? "compressed " : "") + what + ": needed " +
                               std::to_string(n) + " bytes, got " + std::to_string(got));
}
void ByteStream::skip(uint64_t n, const char* what) {
    std::vector<uint8_t> tmp(std::min<uint64_t>(n, 1 << 16));
    while (n > 0) {
        const size_t k = size_t(std::min<uint64_t>(n, tmp.size()));
        read(tmp.data(), k, what);
        n -= k;
    }
}
void ByteStream::finish() {
    if (!compressed_) return;
    std::vector<uint8_t> tmp(1 << 16);
    while (readSome(tmp.data(), tmp.size()) == tmp.size()) {
    }
}

size_t ByteStream::readSome(uint8_t* dst, size_t n) {
    if (!compressed_) return std::fread(dst, 1, n, f_);
    z_.next_out = dst;
    z_.avail_out = uInt(n);
    while (z_.avail_out > 0 && !ended_) step();
    return n - z_.avail_out;
}
// One inflate call (or the input it needs). Ends cleanly only at the end of the file
// after a complete member (optionally followed by zero padding, as gzip -d accepts).
void ByteStream::step() {
    if (z_.avail_in == 0) {
        const size_t k = std::fread(in_, 1, sizeof(in_), f_);
        if (k == 0) {
            if (std::ferror(f_)) throw Error(path_, "read error in compressed data");
            if (inMember_)
                throw Error(path_, "truncated compressed data: the file ends before the end of the " + format() +
                                       " stream and its " + trailer() + " trailer");
            ended_ = true;
            return;
        }
        z_.next_in = in_;
        z_.avail_in = uInt(k);
    }
    if (!inMember_ && members_ > 0) {
        // after a complete member: zero padding to the end of the file, or another member
        while (z_.avail_in > 0 && *z_.next_in == 0) {
            ++z_.next_in;
            --z_.avail_in;
            padding_ = true;
        }
        if (z_.avail_in == 0) return;
        if (padding_) throw Error(path_, "unexpected bytes after the end of the compressed data");
        if (inflateReset(&z_) != Z_OK) throw Error(path_, "cannot reset zlib");
    }
    if (!inMember_) gzip_ = z_.avail_in >= 2 && z_.next_in[0] == 0x1f && z_.next_in[1] == 0x8b;
    inMember_ = true;
    const uInt before = z_.avail_in;
    const int r = inflate(&z_, Z_NO_FLUSH);
    if (r == Z_STREAM_END) {
        inMember_ = false;
        ++members_;
        return;
    }
    if (r == Z_OK || (r == Z_BUF_ERROR && (z_.avail_in == 0 || z_.avail_in != before))) return;
    const std::string msg = z_.msg ? z_.msg : "error " + std::to_string(r);
    if (msg == "incorrect data check" || msg == "incorrect length check")
        throw Error(path_,
                    "corrupt compressed data: " + trailer() + " trailer does not match the data (zlib: " + msg + ")");
    throw Error(path_, "corrupt compressed data (zlib: " + msg + ")");
}

}  // namespace rtfact::io
