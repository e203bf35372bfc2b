#!/usr/bin/env bash
# The CLI's output files and memory budgets under failure (issue 41, items 3, 4 and 8): a failed
# write exits 1 with a message naming the path and the cause, and leaves what was there (a file,
# a symbolic link, a device); no temporary file is left behind.
#   TestCliOutput.sh SPACESKIP WORKDIR CASE
# Write errors on regular files come from `ulimit -f 0` (EFBIG, the signal ignored): the same
# path through the code as a full disk, without one. /dev/full is reached through a symbolic link
# in WORKDIR, so even a regression removes only the link, never the device node.
set -u
exe=$1
work=$2/$3
case=$3
rm -rf "$work"
mkdir -p "$work"
cd "$work" || exit 2

fail() { echo "FAIL ($case): $*" >&2; exit 1; }
# run EXPECTED_RC REGEX CMD...: the exit status and a match in stderr (read through a pipe: the
# file-size limit of `limited` applies to regular files only).
run() {
  local want=$1 re=$2 err rc
  shift 2
  err=$("$@" 2>&1 >/dev/null)
  rc=$?
  echo "$err"
  [ "$rc" = "$want" ] || fail "exit status $rc, expected $want: $*"
  [ -z "$re" ] || grep -Eq -e "$re" <<<"$err" || fail "stderr does not match '$re'"
}
# The bytes written by a failing run are refused by the file-size limit; SIGXFSZ is ignored so
# that write() returns EFBIG instead of killing the process.
limited() { (trap '' XFSZ; ulimit -f 0; exec "$@"); }
no_temp_left() {
  local left
  left=$(find . -name '.*.tmp' | head -n 1)
  [ -z "$left" ] || fail "temporary file left behind: $left"
}
same() { cmp -s "$1" "$2" || fail "$1 changed"; }

small=(gen:menger:16 --size 16x16)
printf 'old contents\n' >keep.orig
cp keep.orig keep.png

case $case in
  png_symlink_write_error)
    ln -s keep.png link.png
    run 1 "link.png: cannot write: File too large" limited "$exe" render "${small[@]}" -o link.png
    [ -L link.png ] || fail "the symbolic link was removed"
    same keep.png keep.orig
    no_temp_left ;;
  png_symlink_written_through)
    ln -s keep.png link.png
    run 0 "" "$exe" render "${small[@]}" -o link.png
    [ -L link.png ] || fail "the symbolic link was replaced by a file"
    head -c 8 keep.png | od -c | grep -q "P   N   G" || fail "the link's target is not the new PNG"
    no_temp_left ;;
  png_file_write_error)
    run 1 "keep.png: cannot write: File too large" limited "$exe" render "${small[@]}" -o keep.png
    same keep.png keep.orig
    no_temp_left ;;
  png_parent_is_file)
    run 1 "keep.png/x.png: cannot write: 'keep.png' is not a folder" "$exe" render "${small[@]}" -o keep.png/x.png
    same keep.png keep.orig ;;
  png_missing_folder)
    run 1 "nodir/x.png: cannot write: the folder 'nodir' does not exist" "$exe" render "${small[@]}" -o nodir/x.png ;;
  png_target_is_directory)
    mkdir d
    run 1 "d: cannot write: is a directory" "$exe" render "${small[@]}" -o d
    [ -d d ] || fail "the directory is gone" ;;
  png_device_full)
    [ -c /dev/full ] || { echo "no /dev/full: skipped"; exit 0; }
    ln -s /dev/full full.png
    run 1 "cannot write: No space left on device" "$exe" render "${small[@]}" -o full.png
    [ -L full.png ] || fail "the symbolic link to /dev/full was removed" ;;
  nrrd_write_error)
    ln -s keep.png vol.nrrd
    run 1 "vol.nrrd: cannot write: File too large" limited "$exe" generate shell --dims 8 8 8 -o vol.nrrd
    [ -L vol.nrrd ] || fail "the symbolic link was removed"
    same keep.png keep.orig
    no_temp_left ;;
  raw_write_error)
    cp keep.orig v_8x8x8_uint8.raw
    run 1 "v_8x8x8_uint8.raw: cannot write: File too large" limited "$exe" generate shell --dims 8 8 8 -o v_8x8x8_uint8.raw
    same v_8x8x8_uint8.raw keep.orig
    no_temp_left ;;
  bench_json_missing_folder)
    run 1 "--json nodir/b.json: cannot write: the folder 'nodir' does not exist" \
        "$exe" bench "${small[@]}" --frames 1 --json nodir/b.json ;;
  bench_csv_is_directory)
    mkdir d
    run 1 "--csv d: cannot write: is a directory" "$exe" bench "${small[@]}" --frames 1 --csv d ;;
  bench_json_disk_full)
    ln -s /dev/full full.json
    [ -c /dev/full ] || { echo "no /dev/full: skipped"; exit 0; }
    run 1 "full.json: cannot write: No space left on device" "$exe" bench "${small[@]}" --frames 1 --json full.json
    [ -L full.json ] || fail "the symbolic link to /dev/full was removed" ;;
  bench_csv_write_error)
    run 1 "keep.png: cannot write: File too large" limited "$exe" bench "${small[@]}" --frames 1 --csv keep.png
    same keep.png keep.orig
    no_temp_left ;;
  bench_paper_json_missing_folder)
    run 1 "--json nodir/p.json: cannot write: the folder 'nodir' does not exist" \
        "$exe" bench --paper --scale 0.05 --datasets aneurism --builders naive --size 16x16 --frames 1 --json nodir/p.json ;;
  bench_paper_json_write_error)
    run 1 "keep.png: cannot write: File too large" limited "$exe" bench --paper --scale 0.05 --datasets aneurism \
        --builders naive --size 16x16 --frames 1 --json keep.png
    same keep.png keep.orig
    no_temp_left ;;
  accuracy_csv_missing_folder)
    run 1 "--csv nodir/a.csv: cannot write: the folder 'nodir' does not exist" \
        "$exe" accuracy gen:menger:16 --size 16x16 --csv nodir/a.csv ;;
  volume_out_of_memory)
    # 512 MiB of float voxels present (a sparse file) and 384 MiB of address space: the
    # allocation fails and the message names the file, the dims and the bytes.
    truncate -s 536870912 big_512x512x512_float32.raw || { echo "no sparse files: skipped"; exit 0; }
    run 1 "big_512x512x512_float32.raw: out of memory allocating 512x512x512 float32 voxels \(536870912 bytes\)" \
        bash -c "ulimit -v 393216; exec \"$exe\" render big_512x512x512_float32.raw --size 16x16 -o x.png" ;;
  *) fail "unknown case" ;;
esac
echo "ok: $case"
