#pragma once
// Whole-file writes that a reader (or a later run) never sees half done.

#include <filesystem>
#include <string_view>

namespace sewn::io {

/// Writes `content` to `<path>.part` in the same folder, then renames it over `path`: a reader
/// sees the old file or the new one, never a part. On any failure (no permission, full disk,
/// file size limit) the temporary is removed, `path` keeps its old content, and FileError names
/// `path` with the system's reason. Cost: one write of `content`.
void write_file_atomically(const std::filesystem::path& path, std::string_view content);

/// Renames a finished `<path>.part` over `path` (removing the part on failure); FileError names
/// `path`. For writers that produce the temporary themselves (cairo's PNG writer).
void publish_part(const std::filesystem::path& part, const std::filesystem::path& path);

}  // namespace sewn::io
