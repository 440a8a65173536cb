#pragma once
/// @file The exceptions strata throws at its API boundaries.

#include <stdexcept>
#include <string>

namespace strata {

/// Bad input: a parameter out of range, a malformed scene, a file whose content is wrong.
/// The message names the function or file, the field or position, and the value.
class InvalidInput : public std::invalid_argument {
  public:
    using std::invalid_argument::invalid_argument;
};

/// A file could not be read or written (missing, unreadable, disk full ...).
class IoError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

/// A progress callback returned false; the operation stopped and left its input unchanged.
class Cancelled : public std::runtime_error {
  public:
    Cancelled() : std::runtime_error("cancelled by the progress callback") {}
};

}  // namespace strata
