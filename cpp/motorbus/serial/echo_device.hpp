// The simplest LineDevice: answers every line with prefix + line + terminator.
// For benchmarks, smoke tests and as a template for drive simulators.
#pragma once
#include <string>
#include <string_view>

#include "motorbus/serial/line_device.hpp"

namespace motorbus::serial {

class EchoLineDevice : public LineDevice {
public:
    explicit EchoLineDevice(std::string prefix = "", std::string reply_terminator = "\r\n",
                            std::string request_terminator = "\r")
        : prefix_(std::move(prefix)), reply_term_(std::move(reply_terminator)),
          request_term_(std::move(request_terminator)) {}
    std::string on_line(std::string_view line) override {
        std::string out;
        out.reserve(prefix_.size() + line.size() + reply_term_.size());
        out.append(prefix_).append(line).append(reply_term_);
        return out;
    }
    std::string request_terminator() const override { return request_term_; }

private:
    std::string prefix_, reply_term_, request_term_;
};

}  // namespace motorbus::serial
