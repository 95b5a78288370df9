#include "tyndall/core/error.h"

#include <sstream>

namespace tyndall {

namespace {
std::string describe(const InputLocation& where, const std::string& message) {
    std::ostringstream out;
    if (!where.file.empty()) {
        out << where.file;
        if (where.line > 0) {
            out << ':' << where.line;
            if (where.column > 0) out << ':' << where.column;
        }
        out << ": ";
    }
    if (!where.field.empty()) out << where.field << ": ";
    out << message;
    return out.str();
}
}  // namespace

InputError::InputError(InputLocation where, std::string message)
    : std::runtime_error(describe(where, message)), where_(std::move(where)), message_(std::move(message)) {}

InputError InputError::withFile(const std::string& file) const {
    InputLocation w = where_;
    if (w.file.empty()) w.file = file;
    return InputError(w, message_);
}

void contractFailure(const char* expr, const char* file, int line, const std::string& message) {
    std::ostringstream out;
    out << file << ':' << line << ": contract violated: " << expr;
    if (!message.empty()) out << " (" << message << ")";
    throw ContractError(out.str());
}

}  // namespace tyndall
