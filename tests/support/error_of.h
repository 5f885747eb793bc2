#pragma once
// error_of(): the glint::Error an action throws, for tests that check what an error names.
#include <gtest/gtest.h>

#include "core/error.h"

namespace glint::test {

// The glint::Error that `action` throws (a test failure when it throws none).
template <class Action>
Error error_of(Action&& action) {
  try {
    action();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no glint::Error was thrown";
  return Error("", "", "no error");
}

}  // namespace glint::test
