# The table of a run's stages (scripts/env.sh, dyadfmu_stages_summary). Input lines:
# START NAME END TICKS STATUS, sorted by START (END, TICKS and STATUS are "-" for a stage
# stopped while it ran); variables: t0 and t1 (the run's start and end), rc (its status),
# hz (clock ticks per second), cpu (the run's CPU ticks), cores, load0 and load1.
BEGIN {
    print ""
    print "== stages: start and wall in seconds from the run's start, CPU = user + system seconds"
    printf "   %-18s %8s %8s %8s  %s\n", "stage", "start", "wall", "CPU", "result"
}
{
    if ($3 == "-") {
        wall = sprintf("%.1f", t1 - $1); used = "-"; result = "stopped (the run ended)"
    } else if ($5 == "stopped") {
        wall = sprintf("%.1f", $3 - $1); used = sprintf("%.1f", $4 / hz); result = "stopped (the run ended)"
    } else {
        wall = sprintf("%.1f", $3 - $1); used = sprintf("%.1f", $4 / hz)
        result = $5 == 0 ? "ok" : "FAILED (exit " $5 ")"
        if ($5 != 0) failed = failed " " $2
    }
    printf "   %-18s %8.1f %8s %8s  %s\n", $2, $1 - t0, wall, used, result
    stages += 1
}
END {
    total = t1 - t0
    printf "   %-18s %8s %8.1f %8.1f  %s\n", "total", "", total, cpu / hz,
        rc == 0 ? "ok" : (failed != "" ? "FAILED:" failed : "FAILED (exit " rc ")")
    printf "   %d stages in %d min %02d s on %d cores; load average (1 min) %s at the start, %s at the end\n",
        stages, int(total / 60), int(total % 60), cores, load0, load1
}
