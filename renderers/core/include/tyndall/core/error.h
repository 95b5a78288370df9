// Two kinds of failure, kept apart (model: filament's Panic.h, pbrt-v4's error.h):
//  - a broken contract inside Tyndall is a programming error: TY_CHECK throws ContractError with file and line;
//  - bad user input (a project file, a parameter, a table, an image) is an InputError that names the file, the
//    field and what is allowed. The CLI maps InputError to exit code 2 and everything else to 1.
#pragma once

#include <stdexcept>
#include <string>

namespace tyndall {

class ContractError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

// Where in the user's input the problem is. Every part is optional; what() joins those present:
// "scene.json:12:5: lights[2].radiance: must be >= 0, got -1".
struct InputLocation {
    std::string file;   // path as the user gave it
    int line = 0;       // 1-based, 0 when unknown
    int column = 0;     // 1-based, 0 when unknown
    std::string field;  // field path such as "lights[2].radiance"
};

class InputError : public std::runtime_error {
public:
    InputError(InputLocation where, std::string message);
    explicit InputError(std::string message) : InputError(InputLocation{}, std::move(message)) {}

    const InputLocation& where() const { return where_; }
    const std::string& message() const { return message_; }

    // The same error with a file name filled in (when the error was raised before the file was known).
    InputError withFile(const std::string& file) const;

private:
    InputLocation where_;
    std::string message_;
};

// The environment refused an operation that the input asked for correctly: a full disk, a read-only folder, missing
// permissions. Not the user's input: the CLI exits 1 for it (docs/conventions.md, "Exit codes").
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// A render that was stopped by its caller. Not an error for the user; the CLI reports it and exits 1.
class Cancelled : public std::runtime_error {
public:
    Cancelled() : std::runtime_error("cancelled") {}
};

[[noreturn]] void contractFailure(const char* expr, const char* file, int line, const std::string& message);

}  // namespace tyndall

#define TY_CHECK(cond, msg)                                                   \
    do {                                                                      \
        if (!(cond)) ::tyndall::contractFailure(#cond, __FILE__, __LINE__, (msg)); \
    } while (false)
