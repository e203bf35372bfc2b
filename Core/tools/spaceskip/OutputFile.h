// Output files written so that a failed write leaves what was there: every file the CLI writes
// (PNG, JSON, CSV, NRRD, raw) goes through OutputFile.
#pragma once
#include <memory>
#include <ostream>
#include <string>

namespace spaceskip {

/// One output file, written whole or not at all. The constructor checks the target and opens a
/// temporary file beside it (".NAME.XXXXXX.tmp" in the same folder, so the rename cannot cross
/// file systems); stream() writes there; commit() flushes, syncs and renames it onto the target.
/// Until commit() succeeds the target is untouched. On any failure, and when the object is
/// destroyed without commit(), the temporary file is removed.
///  - A symbolic link is followed to its final target, and the temporary file is renamed onto
///    that: the link survives and shows the new contents. A dangling link creates its target.
///  - An existing target that is not a regular file or folder (a device such as /dev/null or
///    /dev/full, a FIFO) cannot be replaced by a rename: it is opened and written directly
///    (a FIFO without a reader is an error rather than a wait). A device is never removed.
///  - New files get the permissions of the umask; a replaced file keeps its mode.
/// Errors are std::runtime_error "PATH: cannot write: CAUSE" (the path as given, the system's
/// reason: "No space left on device", "Permission denied", "the folder 'F' does not exist",
/// "is a directory"), thrown by the constructor for what can be known before any data is
/// written, else by commit().
class OutputFile {
 public:
  explicit OutputFile(const std::string& path);
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  /// Where the contents go until commit(); a failed write shows in the stream's state and is
  /// reported by commit().
  std::ostream& stream();
  /// Flushes, syncs and renames the temporary file onto the target (regular files), or flushes
  /// and closes the target (devices, FIFOs); throws on any failure, leaving the target as it was.
  void commit();
  /// The path as given.
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `bytes` written to `path` through an OutputFile (committed, or an exception).
void writeOutputFile(const std::string& path, const std::string& bytes);

}  // namespace spaceskip
