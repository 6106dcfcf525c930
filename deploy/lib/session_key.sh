# Sourced by the deploy scripts (run_demo.sh, run_session.sh).
# make_session_key NAME KEY_FILE LOG: unless $key is set already, makes a new session key
# in KEY_FILE with $bin/snapthread-keygen (its output in LOG) and sets $key; if that
# fails, prints why as NAME and exits 1. The binaries refuse a key whose directory group
# or others may write (docs/security.md), so that directory (the run's own output folder,
# made by the caller) loses its group and other write bits first.
make_session_key() {
  [ -z "$key" ] || return 0
  key=$2
  chmod go-w "$(dirname "$key")" 2> "$3" ||
    { echo "$1: could not chmod go-w the key's folder:" >&2; cat "$3" >&2; exit 1; }
  "$bin/snapthread-keygen" --key "$key" > "$3" 2>&1 ||
    { echo "$1: could not make a session key:" >&2; cat "$3" >&2; exit 1; }
}
