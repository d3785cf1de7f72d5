// Read-only memory map of a whole regular file (checked first: opening a named pipe
// without a writer would block).
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace rtfact::io {

class MappedFile {
   public:
    // Throws Error(file, ...) when the file is missing, not regular or cannot be mapped.
    explicit MappedFile(const std::string& file);
    ~MappedFile();
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;

    const std::string& name() const { return name_; }
    const char* data() const { return data_; }
    size_t size() const { return size_; }
    std::string_view bytes() const { return {data_, size_}; }

   private:
    std::string name_;
    const char* data_ = nullptr;
    size_t size_ = 0;
};

}  // namespace rtfact::io
