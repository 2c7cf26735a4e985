# Sourced by tests/boot/boot-test: boot systemd as PID 1 in a root (no systemd-nspawn: the
# host's PID 1 is not systemd), run commands in it, and tear it down leaving nothing behind.

# Units that cannot work in such a root, masked before it boots:
# - systemd-udevd and its sockets, udev-trigger, udev-settle: the root shares the host's
#   kernel devices (devtmpfs and sysfs are not namespaced), so a udevd here would apply its
#   rules to the host's device nodes and re-trigger every host device. Without it libusb's
#   hotplug monitor still starts (netlink), but no uevent reaches it; the postinst skips the
#   udev reload when udevd is not running, as on any host without udev.
# - systemd-logind: needs its own session cgroups and seats; nothing here logs in.
# - e2scrub_reap: looks for ext4 LVM snapshots of the host's disks.
# - the gettys (getty.target): the console is the log file, there is no terminal to log in on.
MASKED_UNITS=(systemd-udevd.service systemd-udevd-control.socket systemd-udevd-kernel.socket
              systemd-udev-trigger.service systemd-udev-settle.service systemd-logind.service
              e2scrub_reap.service getty.target serial-getty@ttyS0.service console-getty.service)

SYSTEMD_PID=""
UNSHARE_PID=""
PIDNS=""

# in_root COMMAND...: runs COMMAND in the booted root (its mount and PID namespaces, root and
# working folder), with a clean environment.
in_root() {
  nsenter -t "$SYSTEMD_PID" -m -p -r -w \
    env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin HOME=/root LC_ALL=C.UTF-8 TERM=dumb \
    DEBIAN_FRONTEND=noninteractive SYSTEMD_PAGER= SYSTEMD_COLORS=0 "$@"
}

# root_pids [NAME]: host pids of the processes in the root's PID namespace (named NAME).
root_pids() {
  local p
  [ -n "$PIDNS" ] || return 0
  for p in /proc/[0-9]*; do
    [ "$(readlink "$p/ns/pid" 2>/dev/null)" = "$PIDNS" ] || continue
    if [ -z "${1:-}" ] || [ "$(cat "$p/comm" 2>/dev/null)" = "$1" ]; then echo "${p#/proc/}"; fi
  done
}

# reap_stale_roots: what a run killed from outside (a ctest timeout's SIGKILL skips the trap)
# left behind: each earlier root's systemd, then its folder.
reap_stale_roots() {
  local dir pid
  for dir in /var/tmp/atelier-boot-test.*; do
    [ -d "$dir" ] && [ "$dir" != "${RUN:-}" ] || continue
    pid=$(cat "$dir/systemd.pid" 2>/dev/null)
    if [ -n "$pid" ] && [ "$(readlink "/proc/$pid/root" 2>/dev/null)" = "$dir/root" ]; then
      echo "boot-test: killing the systemd (pid $pid) of an earlier run in $dir"
      kill -KILL "$pid"
      sleep 1
    fi
    grep -qF " $dir" /proc/self/mountinfo || rm -rf "$dir"
  done
}

boot_container() {
  local unit state deadline
  for unit in "${MASKED_UNITS[@]}"; do ln -sf /dev/null "$ROOT/etc/systemd/system/$unit"; done
  cp /etc/resolv.conf "$ROOT/etc/resolv.conf"   # apt reaches the mirror by name
  echo atelier-boot-test > "$ROOT/etc/hostname"
  echo "deb $MIRROR bookworm main" > "$ROOT/etc/apt/sources.list"
  # A throw-away root: dpkg need not fsync every file it unpacks (about 200 packages).
  echo force-unsafe-io > "$ROOT/etc/dpkg/dpkg.cfg.d/boot-test-unsafe-io"
  : > "$RUN/console.log"
  # In the new mount namespace, before systemd starts: the root bound onto itself, so that
  # its / is a mount point (services' mount namespaces begin by remounting / as a slave, which
  # fails with EINVAL on a plain folder: 226/NAMESPACE); the root's own /dev (debootstrap's
  # static nodes) bound onto itself, so that systemd finds /dev mounted and does not mount the
  # host's devtmpfs there (whose nodes, and their modes, are the host's: this host's /dev/null
  # is 0644, and apt's _apt sandbox could not write to it); and /dev/console is the log file
  # instead of the host's console.
  setsid unshare --pid --fork --mount --mount-proc="$ROOT/proc" sh -c '
      mount --rbind "$1" "$1" && mount --bind "$1/dev" "$1/dev" &&
      mount --bind "$2" "$1/dev/console" &&
      exec chroot "$1" /lib/systemd/systemd --system --log-target=console' \
    sh "$ROOT" "$RUN/console.log" < /dev/null >> "$RUN/console.log" 2>&1 &
  UNSHARE_PID=$!
  deadline=$(( $(date +%s) + 20 ))
  until [ -n "$SYSTEMD_PID" ]; do
    SYSTEMD_PID=$(cat /proc/$UNSHARE_PID/task/*/children 2>/dev/null | awk '{print $1; exit}')
    [ "$(date +%s)" -lt "$deadline" ] || { echo "  systemd did not start" >&2; return 1; }
    [ -n "$SYSTEMD_PID" ] || sleep 0.2
  done
  PIDNS=$(readlink "/proc/$SYSTEMD_PID/ns/pid")
  echo "$SYSTEMD_PID" > "$RUN/systemd.pid"
  echo "  systemd: host pid $SYSTEMD_PID ($PIDNS)"
  # Until the boot is done: running, or degraded when a unit failed (listed, then it fails).
  deadline=$(( $(date +%s) + 120 ))
  while :; do
    state=$(in_root systemctl is-system-running 2>/dev/null)
    case "$state" in running|degraded) break ;; esac
    [ "$(date +%s)" -lt "$deadline" ] || { echo "  still $state after 120 s" >&2; break; }
    sleep 0.5
  done
  echo "  system: $state"
  in_root systemctl --failed --no-legend --no-pager | sed 's/^/  failed: /'
  [ "$state" = running ]
}

# stop_container: SIGKILL to the root's PID 1 ends every process in its PID namespace; the
# mount namespaces go with their last process. Then nothing of the root may be mounted.
stop_container() {
  [ -n "$SYSTEMD_PID" ] || return 0
  kill -KILL "$SYSTEMD_PID" 2>/dev/null
  wait "$UNSHARE_PID" 2>/dev/null
  local deadline=$(( $(date +%s) + 10 ))
  while [ -n "$(root_pids)" ] && [ "$(date +%s)" -lt "$deadline" ]; do sleep 0.2; done
  if [ -n "$(root_pids)" ]; then
    echo "boot-test: processes left in the root: $(root_pids | tr '\n' ' ')" >&2
  fi
  SYSTEMD_PID=""
  if grep -qF " $RUN" /proc/self/mountinfo; then
    echo "boot-test: mounts left under $RUN, not removing it:" >&2
    grep -F " $RUN" /proc/self/mountinfo >&2
    RUN=/nonexistent
  fi
}
