// For tests of option validation: what a call refused with, as text.
#pragma once
#include <exception>
#include <string>

#include "motorbus/errors.hpp"

namespace motorbus::test {

// The InvalidArgument message `f` throws; "no exception" or "wrong exception: ..." otherwise,
// so an EXPECT on the text also shows what happened instead.
template <class F>
std::string invalid_message(F&& f) {
    try {
        f();
    } catch (const InvalidArgument& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("wrong exception: ") + e.what();
    }
    return "no exception";
}

}  // namespace motorbus::test
