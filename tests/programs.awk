# tests/programs.awk - the programs the makefiles given as input know how to
# build: every rule whose target lies under $(B)/ or $(FB)/, but for objects,
# generated headers and stamps. One name a line (without the folder), for
# make's test-programs-build, which holds them against TEST_PROGRAMS.
/^\$\((B|FB)\)\/[^:=]*:/ {
    split($0, part, ":")
    n = split(part[1], target, " ")
    for (i = 1; i <= n; ++i) {
        name = target[i]
        if (name !~ /^\$\((B|FB)\)\//) continue
        sub(/^\$\((B|FB)\)\//, "", name)
        if (name == "" || name ~ /%/ || name ~ /\.(o|h|stamp)$/) continue
        print name
    }
}
