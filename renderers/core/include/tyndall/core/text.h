// Text for people: numbers as they read back, user text cut for messages, the nearest of known names. One copy of each,
// used by every layer (error messages, metadata, the CLI's and the studio's output).
#pragma once

#include "tyndall/core/scene.h"

#include <cstddef>
#include <string>
#include <vector>

namespace tyndall {

// Shortest text that reads back as the same double (for files and messages that must round-trip); "inf", "-inf" and
// "nan" for the special values.
std::string formatNumber(double value);
std::string formatVec3(const Vec3& v);
// Six significant digits ("%.6g"), for metadata and summaries that people read.
std::string formatShort(double value);

// The largest prefix length <= limit that does not cut a UTF-8 sequence of `text`.
std::size_t utf8Boundary(const std::string& text, std::size_t limit);
// User text for an error message, cut to `limit` bytes (at a UTF-8 boundary) with the full length appended, so that a
// 10 MB value does not become a 10 MB message.
std::string clipForMessage(const std::string& text, std::size_t limit = 60);

// The known name closest to `name` by edit distance (case-insensitive), or "" when none is reasonably close.
std::string nearestName(const std::string& name, const std::vector<std::string>& known);

}  // namespace tyndall
