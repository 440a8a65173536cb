#pragma once
// Internal: a loop over indices run side by side (TBB), for per-layer work whose order does not
// matter but whose exceptions must come out as a loop one by one would give them.

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <exception>
#include <vector>

namespace strata::detail {

/// f(i) for every i in [0, n), side by side. When some throw, the exception of the smallest
/// such i is rethrown once every call has ended (the others are dropped).
template <class F>
void parallel_for_each_index(std::size_t n, F&& f) {
    std::vector<std::exception_ptr> failed(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) {
                              try {
                                  f(i);
                              } catch (...) {
                                  failed[i] = std::current_exception();
                              }
                          }
                      });
    for (const std::exception_ptr& e : failed)
        if (e) std::rethrow_exception(e);
}

}  // namespace strata::detail
