// The machine's drop folder (e.g. a USB stick mounted at /media/EMB) that embroidery machines
// read stitch files from: files appear there whole or not at all.
//
// DropFolder is the OS seam: FileDropDevice (daemon/file_drop_device.h) writes through it
// and tests replace it with a fake that fails like a full stick. PosixDropFolder writes each
// file to a hidden temporary name in the same folder, fsyncs it, renames it over the final
// name (never over an existing file: EEXIST) and fsyncs the folder, so a machine (or a pulled
// stick) never sees half a file.
//
// Threading: one instance per caller; not shared.
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

#include "base/error.h"

namespace atelier {

// A write into the drop folder failed. what() names the folder, the file and the OS reason
// ("/media/EMB: no space left on device writing 7-cat.dst").
class DropError : public DeviceError {
 public:
  DropError(const std::string& what, int error_number)
      : DeviceError(what), error_number_(error_number) {}
  int error_number() const { return error_number_; }  // errno, e.g. ENOSPC, ENOENT
 private:
  int error_number_;
};

class DropFolder {
 public:
  virtual ~DropFolder() = default;
  // Whether the folder exists and is a folder (a mounted stick).
  virtual bool present() const = 0;
  // Writes `bytes` as `name` atomically; throws DropError (nothing of `name` is left behind).
  virtual void write_atomically(const std::string& name, std::string_view bytes) = 0;
  // Removes `name` if it is there (to take back a partly delivered job); never throws.
  virtual void remove(const std::string& name) noexcept = 0;
};

class PosixDropFolder : public DropFolder {
 public:
  explicit PosixDropFolder(std::filesystem::path dir) : dir_(std::move(dir)) {}
  bool present() const override;
  void write_atomically(const std::string& name, std::string_view bytes) override;
  void remove(const std::string& name) noexcept override;

 private:
  std::filesystem::path dir_;
};

}  // namespace atelier
