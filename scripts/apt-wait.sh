# Sourced by the scripts that run apt-get (install-deps.sh, blender-chroot.sh): waits
# while another process (unattended-upgrades, another install) holds apt's or dpkg's
# locks, saying so once, instead of failing at once with "Could not get lock".
#
#   wait_for_apt [ROOT]   ROOT: a chroot whose own locks to wait for ("" = the host's)
#
# GLSLPPM_APT_WAIT: the most seconds to wait (default 900). GLSLPPM_APT_LOCKS: lock files
# to watch instead of apt's (the tests use their own). apt-get is also given the same
# wait as DPkg::Lock::Timeout (APT_LOCK_OPTIONS), for a lock taken just after the check.

APT_WAIT_SECONDS=${GLSLPPM_APT_WAIT:-900}
APT_LOCK_OPTIONS=(-o "DPkg::Lock::Timeout=$APT_WAIT_SECONDS")

apt_lock_files() {
  if [ -n "${GLSLPPM_APT_LOCKS:-}" ]; then
    printf '%s\n' $GLSLPPM_APT_LOCKS
  else
    local root=${1:-}
    printf '%s\n' "$root/var/lib/dpkg/lock-frontend" "$root/var/lib/dpkg/lock" \
      "$root/var/lib/apt/lists/lock" "$root/var/cache/apt/archives/lock"
  fi
}

# Prints the first lock file some process holds (flock or fcntl: /proc/locks lists
# both, by inode), or fails when none is held.
apt_lock_held() {
  local file inode
  while read -r file; do
    [ -e "$file" ] || continue
    inode=$(stat -L -c %i "$file") || continue
    if awk -v inode="$inode" '{ for (i = 1; i <= NF; i++) if ($i ~ /^[0-9a-f]+:[0-9a-f]+:[0-9]+$/) {
          split($i, id, ":"); if (id[3] == inode) held = 1 } }
        END { exit held ? 0 : 1 }' /proc/locks; then
      echo "$file"
      return 0
    fi
  done < <(apt_lock_files "$@")
  return 1
}

wait_for_apt() {
  local waited=0 held
  while held=$(apt_lock_held "$@"); do
    if [ "$waited" -eq 0 ]; then
      echo "waiting for $held: another process is using apt/dpkg (up to $APT_WAIT_SECONDS s)" >&2
    fi
    if [ "$waited" -ge "$APT_WAIT_SECONDS" ]; then
      echo "$held is still locked after $waited s: let the other apt/dpkg process finish" \
           "(or stop it) and run this again" >&2
      return 1
    fi
    sleep 1
    waited=$((waited + 1))
  done
  [ "$waited" -eq 0 ] || echo "apt/dpkg is free after $waited s; going on" >&2
  return 0
}
