# SPDX-License-Identifier: GPL-2.0-or-later
# Sourced by test.sh, fuzz.sh and fuzz_cli.sh: the one rule for $JOBS, the
# count of processes a script runs side by side.
# jobs_check SCRIPT: where JOBS is set, exits 2 with a one-line message
# unless it is a whole number from 1 to 9999 (unset: the script's default).
jobs_check() {
    case ${JOBS-} in
        '') return 0 ;;
        *[!0-9]*|?????*) ;;
        *) [ "$JOBS" -ge 1 ] && return 0 ;;
    esac
    echo "$1: JOBS=$JOBS: give a count of processes, 1 to 9999" >&2
    exit 2
}
