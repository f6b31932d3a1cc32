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
// Refuses an output path that a file must not replace (docs/architecture.md §7.5): a symbolic
// link (BadInput: lumislab does not replace links, nor writes through them), a device node, FIFO
// or socket (BadInput: not a regular file; as root, renaming over /dev/null replaces it), a
// folder (IoError: a file cannot take its place). A missing path or a regular file passes. Tools
// call it where they parse --out, so that they refuse before long work; WriteAtomically checks
// again just before its rename.
void CheckOutputPath(const std::string& path);
// BadInput naming `path` when it is a file lumislab reads: inside a slab folder (one holding
// slab.json), or inside the slab/, calib/, calibration/, photos/ or truth/ folder of a dataset
// (a folder holding dataset.json, up to three levels up), or the dataset's dataset.json or
// checks.json; `allowed` (when not empty) is the one such file the caller writes (calibrate
// colour's calib/colour.json). --force replaces an earlier output, never a run's input.
void RefuseOutputOverInputs(const std::string& path, const std::string& allowed = "");
// Calls write(tmp_path), checks final_path (CheckOutputPath), then renames tmp_path onto it. On
// any exception the temporary file is removed and the exception rethrown; a failed rename is an
// IoError (exit 3).
void WriteAtomically(const std::string& final_path,
                     const std::function<void(const std::string& tmp_path)>& write);
void WriteTextAtomically(const std::string& final_path, const std::string& text);
std::string ReadTextFile(const std::string& path);  // IoError when missing/unreadable
// Puts the finished folder `staging` where `final_dir` is: an old folder there is moved aside
// first and removed only once the new one is in place (restored if the move fails; IoError).
void ReplaceFolder(const std::string& staging, const std::string& final_dir);
// Writes the folder `final_dir` through a staging folder beside it (orphaned staging folders of
// interrupted runs there removed first, logged): write(staging) fills it; when it returns true
// the staging folder replaces `final_dir` (ReplaceFolder); when it returns false (a stop signal)
// or throws, the staging folder is removed and `final_dir` is left as it was. Returns what
// write returned.
bool WriteFolderStaged(const std::string& final_dir,
                       const std::function<bool(const std::string& staging)>& write);
bool IsTemporaryName(const std::string& filename);  // starts with '.'
void MakeDirectories(const std::string& dir);       // IoError on failure

}  // namespace lumislab
