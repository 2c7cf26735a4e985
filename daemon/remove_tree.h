// Removing a folder and everything in it without following a symbolic link anywhere: each
// level is opened with openat(O_NOFOLLOW | O_DIRECTORY) from its parent's descriptor and its
// entries are removed with unlinkat, so a symlink (also one swapped in while the removal runs)
// is removed itself and never entered, and nothing outside the folder is touched.
//
// Used for the output folders of purged jobs (daemon/purge.h), which may hold what a user
// dropped (a folder kept in failed/<id>/) and can still change.
// Threading: no state; any thread. Holds one descriptor per level while it works.
#pragma once

#include <string>
#include <system_error>

namespace atelier {

// At most this many levels of folders below the one removed (one descriptor each); a deeper
// tree is left in place and the error is ELOOP.
inline constexpr int kMaxRemoveDepth = 256;

// Removes the entry `name` (a single file name, no '/') of the folder open at `dir_fd`: a file
// or symlink is unlinked, a folder removed with its contents. An entry that is already gone is
// success. Returns the first error (removal stops there), with `failed` set to the path of the
// entry it concerns, relative to `dir_fd`.
std::error_code remove_tree_at(int dir_fd, const std::string& name, std::string& failed);

}  // namespace atelier
