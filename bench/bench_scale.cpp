// Scale table of issue 14: what a user runs, timed as a whole process, beside the library
// calls, on generated stacks of growing size.
//
//   strata_bench_scale [--strata PATH] [--layers L] [--points N[,N...]] [--remove R[,R...]]
//                      [--dir DIR] [--threads T] [--no-naive]
//
// For every N: folded_stack(L, N) (the scene family of strata_bench_cgal, same segment length
// at every size) is written as JSON into DIR; then, in one run,
//   - library calls in this process: read_scene, check_scene (one core);
//   - whole processes (fork + exec, wall time, the child's CPU time (user + system, which a
//     busy machine disturbs less) and its peak resident memory, which includes what this
//     process holds when it forks: scenes are freed and malloc_trim()med first):
//     `strata check IN`, and for every R `strata simplify IN -o OUT --remove R` and the same
//     with `--no-untangle` (naive decimation, the floor any simplifier pays).
// Plain timers, one run per cell: the machine is small and noisy, read ratios.
#include "strata/geometry/checks.h"
#include "strata/io/scene_io.h"
#include "strata/simplify/simplify.h"

#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

using namespace strata;

namespace {

double now() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

struct ProcessRun {
    double seconds = 0.0;      // wall
    double cpu_seconds = 0.0;  // user + system, all threads
    double peak_mib = 0.0;
    int exit_code = -1;
};

// Runs `args` (args[0] the program) with stdout and stderr sent to /dev/null.
ProcessRun run_process(const std::vector<std::string>& args) {
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::fflush(nullptr);  // or the child would write our buffered output again
    const double start = now();
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error("fork failed");
    if (pid == 0) {
        if (!std::freopen("/dev/null", "w", stdout) || !std::freopen("/dev/null", "w", stderr))
            _exit(126);
        execv(argv[0], argv.data());
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    if (wait4(pid, &status, 0, &usage) < 0) throw std::runtime_error("wait4 failed");
    ProcessRun run;
    run.seconds = now() - start;
    run.peak_mib = static_cast<double>(usage.ru_maxrss) / 1024.0;
    auto secs = [](const timeval& t) {
        return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
    };
    run.cpu_seconds = secs(usage.ru_utime) + secs(usage.ru_stime);
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return run;
}

std::vector<double> parse_list(const std::string& text, const char* flag) {
    std::vector<double> values;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma - start);
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !(v > 0.0))
            throw std::runtime_error(std::string(flag) + ": '" + item + "' is not a number > 0");
        values.push_back(v);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return values;
}

int usage() {
    std::fprintf(stderr,
                 "usage: strata_bench_scale [--strata PATH (build/tools/strata)] [--layers L (8)] "
                 "[--points N[,N...] (10000,60000,125000)] [--remove R[,R...] (0.9,0.95)] "
                 "[--dir DIR (strata-bench-scale)] [--threads T (0: all)] [--no-naive]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        std::string strata = "build/tools/strata", dir = "strata-bench-scale", threads = "0";
        std::size_t layers = 8;
        std::vector<double> points{10000, 60000, 125000}, removals{0.9, 0.95};
        bool naive = true;
        for (int k = 1; k < argc; ++k) {
            const std::string arg = argv[k];
            const bool has_value = k + 1 < argc;
            if (arg == "--strata" && has_value)
                strata = argv[++k];
            else if (arg == "--dir" && has_value)
                dir = argv[++k];
            else if (arg == "--threads" && has_value)
                threads = argv[++k];
            else if (arg == "--layers" && has_value)
                layers = static_cast<std::size_t>(parse_list(argv[++k], "--layers").at(0));
            else if (arg == "--points" && has_value)
                points = parse_list(argv[++k], "--points");
            else if (arg == "--remove" && has_value)
                removals = parse_list(argv[++k], "--remove");
            else if (arg == "--no-naive")
                naive = false;
            else
                return usage();
        }
        if (!std::filesystem::exists(strata)) {
            std::fprintf(stderr, "strata_bench_scale: no strata executable at '%s' (--strata)\n",
                         strata.c_str());
            return 2;
        }
        std::filesystem::create_directories(dir);
        std::printf(
            "| layers x vertices | read (lib) | check (lib) | `strata check` | peak MiB |\n");
        std::printf("|---|---|---|---|---|\n");
        struct Row {
            std::string label, path;
        };
        std::vector<Row> rows;
        for (double n : points) {
            const auto count = static_cast<std::size_t>(n);
            const std::string label = std::to_string(layers) + " x " + std::to_string(count);
            const std::string path =
                dir + "/stack_" + std::to_string(layers) + "x" + std::to_string(count) + ".json";
            rows.push_back({label, path});
            double read_s = 0.0, check_s = 0.0;
            bool clean = false;
            {
                write_scene(folded_stack(layers, count, 10.0 * n / 600.0), path);
                double t = now();
                const Scene read = read_scene(path);
                read_s = now() - t;
                t = now();
                clean = check_scene(read).is_collision_free();
                check_s = now() - t;
            }
            // A forked child starts with our resident pages in its peak: give them back first.
            malloc_trim(0);
            const ProcessRun cli = run_process({strata, "check", path});
            std::printf("| %s | %.3f s | %.3f s (%s) | %.3f s (cpu %.3f s, exit %d) | %.0f |\n",
                        label.c_str(), read_s, check_s, clean ? "clean" : "NOT clean", cli.seconds,
                        cli.cpu_seconds, cli.exit_code, cli.peak_mib);
            std::fflush(stdout);
        }
        std::printf(
            "\n| layers x vertices | removal | `strata simplify` | peak MiB | per removal |"
            "%s\n",
            naive ? " naive (`--no-untangle`) | peak MiB | strata / naive |" : "");
        std::printf("|---|---|---|---|---|%s\n", naive ? "---|---|---|" : "");
        for (const Row& row : rows) {
            const double total =
                static_cast<double>(layers) * std::stod(row.label.substr(row.label.find('x') + 2));
            for (double r : removals) {
                char remove[32];
                std::snprintf(remove, sizeof remove, "%g", r);
                const std::string out = row.path + ".out.json";
                const ProcessRun s = run_process({strata, "simplify", row.path, "-o", out,
                                                  "--remove", remove, "--threads", threads});
                const double per_removal_us = s.seconds / (total * r) * 1e6;
                std::printf("| %s | %s | %.3f s (cpu %.3f s, exit %d) | %.0f | %.2f us |",
                            row.label.c_str(), remove, s.seconds, s.cpu_seconds, s.exit_code,
                            s.peak_mib, per_removal_us);
                if (naive) {
                    const ProcessRun nv =
                        run_process({strata, "simplify", row.path, "-o", out, "--remove", remove,
                                     "--threads", threads, "--no-untangle"});
                    std::printf(" %.3f s (cpu %.3f s, exit %d) | %.0f | %.2f |", nv.seconds,
                                nv.cpu_seconds, nv.exit_code, nv.peak_mib, s.seconds / nv.seconds);
                }
                std::printf("\n");
                std::fflush(stdout);
            }
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "strata_bench_scale: %s\n", e.what());
        return 2;
    }
}
