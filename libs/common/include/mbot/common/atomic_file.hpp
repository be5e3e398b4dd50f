// Whole-or-nothing file output: write to a temporary file beside the target, then rename, so a
// reader never sees half a file, even when the run is interrupted.
#pragma once

#include <fstream>
#include <functional>
#include <ostream>
#include <string>

namespace mbot {

// Calls `write` on a stream to a temporary file in the target's folder and renames it over `path`
// when `write` returns and the stream is good. Throws std::runtime_error naming the path otherwise
// (and leaves any previous file at `path` untouched).
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

// The same for a file written a piece at a time over a long run (a per-scan trajectory): the
// pieces go to a temporary file beside `path`, which Commit renames over it. Destroyed without
// Commit (an error, or a run that wrote nothing worth keeping), the temporary file is removed.
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(std::string path);  // throws naming the path when it cannot create the file
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  ~AtomicFileWriter();

  std::ostream& stream() { return out_; }
  const std::string& path() const { return path_; }
  // Flushes and renames; throws naming the path when a write failed (disk full?).
  void Commit();

 private:
  std::string path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

// Renames an already written temporary file over `path` (for writers that need a file name, such
// as OpenCV's imwrite). `tmp` must be in the same folder.
void CommitFile(const std::string& tmp, const std::string& path);
// A temporary file name beside `path` keeping its extension (so format-by-extension writers work).
std::string TempPathFor(const std::string& path);

// Removes the temporary files of `path` (TempPathFor's names) that a process no longer running left
// behind (killed before it could rename or remove them). Returns how many it removed.
int RemoveStaleTempFiles(const std::string& path);

// Creates `dir` and its parents; throws naming the folder when it cannot.
void EnsureDirectory(const std::string& dir);

}  // namespace mbot
