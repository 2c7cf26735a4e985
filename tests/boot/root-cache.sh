# Sourced by tests/boot/boot-test: the minimal bookworm root, made once by debootstrap and kept
# as a tarball under $CACHE keyed by the debootstrap command (another command, another key),
# and the root's apt lists and downloaded .debs kept beside it so a run downloads only what
# changed on the mirror.

DEBOOTSTRAP_CMD=(debootstrap --variant=minbase --include=systemd,systemd-sysv,dbus,udev
                 bookworm ROOT http://deb.debian.org/debian)

root_tarball() {
  local key
  key=$(printf '%s\n' "${DEBOOTSTRAP_CMD[@]}" | sha256sum | cut -c1-16)
  echo "$CACHE/root-$key.tar"
}

# make_root DIR: DIR becomes a fresh copy of the cached root (made first if missing).
make_root() {
  local dir=$1 tarball tmp
  tarball=$(root_tarball)
  mkdir -p "$CACHE/apt-archives/partial" "$CACHE/apt-lists/partial"
  if [ ! -f "$tarball" ]; then
    echo "boot-test: making the cached root $tarball (debootstrap, about a minute)"
    tmp=$(mktemp -d "$CACHE/debootstrap.XXXXXX")
    local cmd=("${DEBOOTSTRAP_CMD[@]}")
    for i in "${!cmd[@]}"; do [ "${cmd[$i]}" = ROOT ] && cmd[$i]=$tmp/root; done
    if ! "${cmd[@]}" > "$tmp/debootstrap.log" 2>&1; then
      tail -20 "$tmp/debootstrap.log" >&2
      echo "boot-test: debootstrap failed (log: $tmp/debootstrap.log)" >&2
      return 1
    fi
    # debootstrap's own downloads seed the apt cache; the tarball stays small without them.
    find "$tmp/root/var/cache/apt/archives" -maxdepth 1 -name '*.deb' -exec mv -t "$CACHE/apt-archives" {} +
    tar -C "$tmp/root" -cf "$tarball.tmp" . && mv "$tarball.tmp" "$tarball"
    rm -rf "$tmp"
  fi
  mkdir -p "$dir"
  tar -C "$dir" -xf "$tarball"
  # apt's cache: hard links (same file system) or copies of the kept files.
  cp -al "$CACHE/apt-archives/." "$dir/var/cache/apt/archives/" 2>/dev/null ||
    cp -a "$CACHE/apt-archives/." "$dir/var/cache/apt/archives/"
  cp -a "$CACHE/apt-lists/." "$dir/var/lib/apt/lists/"
}

# keep_apt_cache DIR: what apt downloaded into DIR goes back into the cache for the next run.
keep_apt_cache() {
  local dir=$1
  find "$dir/var/cache/apt/archives" -maxdepth 1 -name '*.deb' \
    -exec cp -n -t "$CACHE/apt-archives" {} + 2>/dev/null || true
  rm -rf "$CACHE/apt-lists.new"
  if cp -a "$dir/var/lib/apt/lists" "$CACHE/apt-lists.new" 2>/dev/null; then
    rm -f "$CACHE/apt-lists.new/lock"
    rm -rf "$CACHE/apt-lists" && mv "$CACHE/apt-lists.new" "$CACHE/apt-lists"
  fi
}
