// strata: the command-line front end. Each verb lives in its own cmd_*.cpp.
#include "cli_util.h"
#include "commands.h"
#include "time_limit.h"

#include "strata/core/error.h"

#include <cstdio>
#include <exception>
#include <iostream>
#include <map>
#include <new>
#include <string>

int main(int argc, char** argv) {
    CLI::App app{"strata: collision-free simplification of 2D multi-layered shapes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "strata 0.1.0");
    std::map<std::string, strata::cli::Run> verbs;
    verbs["check"] = strata::cli::add_check_command(app);
    verbs["slice"] = strata::cli::add_slice_command(app);
    verbs["untangle"] = strata::cli::add_untangle_command(app);
    verbs["simplify"] = strata::cli::add_simplify_command(app);
    verbs["grid"] = strata::cli::add_grid_command(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "strata: error: " << e.what() << "\n(run 'strata --help' for usage)\n";
        return 2;
    }
    // An error after a verb started: a progress bar it left unfinished is ended first, so that
    // the message has a line of its own. Returns the exit code.
    auto fail = [](int code, const std::string& message) {
        strata::cli::end_progress_line();
        std::cerr << "strata: error: " << message << '\n';
        return code;
    };
    try {
        for (auto& [name, run] : verbs)
            if (app.got_subcommand(name)) return run();
    } catch (const strata::InvalidInput& e) {
        return fail(2, e.what());
    } catch (const strata::IoError& e) {
        return fail(2, e.what());
    } catch (const strata::Cancelled& e) {
        return fail(1, e.what());
    } catch (const strata::cli::TimeLimitReached& e) {
        return fail(1, e.what());
    } catch (const std::bad_alloc&) {
        // Outputs are written atomically (a batch writes each slice's when it is done).
        return fail(1,
                    "out of memory: the input needs more memory than this process may use "
                    "(machine or ulimit); no partial output written");
    } catch (const std::exception& e) {
        return fail(1, std::string("internal: ") + e.what());
    }
    return 2;
}
