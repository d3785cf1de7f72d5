// Errors about a file or an input: printed by the CLI as
//   rtfact: error: <file>: <what is wrong>
#pragma once
#include <stdexcept>
#include <string>

namespace rtfact {

class Error : public std::runtime_error {
   public:
    Error(std::string file, const std::string& what) : std::runtime_error(what), file_(std::move(file)) {}
    const std::string& file() const { return file_; }
    // "<file>: <what>" (or just "<what>" when no file is concerned)
    std::string message() const { return file_.empty() ? std::string(what()) : file_ + ": " + what(); }

   private:
    std::string file_;
};

}  // namespace rtfact
