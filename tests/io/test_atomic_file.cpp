// write_file_atomic() under SIGKILL (issue 16, item 4): a child process rewrites a file of
// several MB over and over and is killed at spread-out moments, nearly always inside a write;
// the file must then hold one whole version (the old one or a new one), never a mix or a part.
#include "strata/core/error.h"
#include "strata/io/atomic_file.h"

#include <catch2/catch.hpp>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

using namespace strata;

namespace {

constexpr std::size_t kSize = 8u << 20;  // 8 MiB: a write takes milliseconds

// Version k: kSize bytes of the letter 'a' + k % 26, framed so that a truncation shows.
std::string version(int k) {
    std::string s(kSize, static_cast<char>('a' + k % 26));
    const std::string head = "BEGIN " + std::to_string(k) + "\n";
    s.replace(0, head.size(), head);
    s.replace(s.size() - 4, 4, "END\n");
    return s;
}

// The version a whole file holds, or -1.
int whole_version(const std::string& content) {
    if (content.size() != kSize || content.compare(0, 6, "BEGIN ") != 0 ||
        content.compare(content.size() - 4, 4, "END\n") != 0)
        return -1;
    const int k = std::atoi(content.c_str() + 6);
    return content == version(k) ? k : -1;
}

}  // namespace

TEST_CASE("write_file_atomic: SIGKILL in the middle leaves a whole version", "[io][faults]") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("strata_test_atomic_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto path = dir / "out.bin";
    write_file_atomic(path, version(0));

    // Kills until 8 of them have landed inside a write (a temporary file is left): where a
    // kill lands is timing (writing 8 MiB takes about as long as the rename that frees the old
    // file), so the number of trials is not fixed; every kill must leave a whole version.
    int kills = 0, inside_writes = 0;
    for (int trial = 0; trial < 400 && inside_writes < 8; ++trial) {
        const pid_t child = ::fork();
        REQUIRE(child >= 0);
        if (child == 0) {
            // The versions are made before the loop: the child spends its time writing.
            const std::string odd = version(2 * trial + 1), even = version(2 * trial + 2);
            for (int k = 1;; ++k) write_file_atomic(path, k % 2 ? odd : even);  // until killed
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20 + 3 * (trial % 16)));
        REQUIRE(::kill(child, SIGKILL) == 0);
        int status = 0;
        REQUIRE(::waitpid(child, &status, 0) == child);
        CHECK(WIFSIGNALED(status));
        ++kills;
        CHECK(whole_version(read_text_file(path)) >= 0);
        // The temporary file of the interrupted write stays beside the target (nothing can
        // remove it after SIGKILL); it never takes the target's name.
        bool stale = false;
        for (const auto& entry : std::filesystem::directory_iterator(dir))
            if (entry.path() != path) {
                stale = true;
                std::filesystem::remove(entry.path());
            }
        inside_writes += stale ? 1 : 0;
    }
    INFO("kills: " << kills << ", inside a write: " << inside_writes);
    CHECK(inside_writes == 8);  // the kills did land inside writes
    std::filesystem::remove_all(dir);
}
