// Atomic writes (docs/formats.md): write under a temporary name in the same folder, then rename.
// Temporary names start with '.', keep the extension (so encoders pick the format) and are
// ignored by every folder watcher.
#pragma once

#include <functional>
#include <string>

namespace lumislab {

// "dir/.name.tmp<pid>_<n>.ext" for "dir/name.ext"; the name part is shortened so that the
// temporary name stays within 255 bytes when the final one does.
std::string TemporaryPathFor(const std::string& final_path);
// Removes the temporary files (and staging folders) in `dir` left by lumislab processes that no
// longer run (killed mid-write): names of TemporaryPathFor's form whose pid is gone. Returns how
// many.
int RemoveOrphanedTemporaries(const std::string& dir);
// Calls write(tmp_path), then renames tmp_path onto final_path. On any exception the temporary
// file is removed and the exception rethrown; a failed rename is an IoError (exit 3).
void WriteAtomically(const std::string& final_path,
                     const std::function<void(const std::string& tmp_path)>& write);
void WriteTextAtomically(const std::string& final_path, const std::string& text);
std::string ReadTextFile(const std::string& path);  // IoError when missing/unreadable
// Puts the finished folder `staging` where `final_dir` is: an old folder there is moved aside
// first and removed only once the new one is in place (restored if the move fails; IoError).
void ReplaceFolder(const std::string& staging, const std::string& final_dir);
bool IsTemporaryName(const std::string& filename);  // starts with '.'
void MakeDirectories(const std::string& dir);       // IoError on failure

}  // namespace lumislab
