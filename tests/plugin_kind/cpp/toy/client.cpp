#include <charconv>
#include <cmath>
#include <string>

#include "motorbus/errors.hpp"
#include "toy/toy.hpp"

namespace motorbus::toy {

namespace {
// Joins text pieces with append (GCC 12's -Wrestrict misreads chains of operator+ on strings).
template <class... Parts>
std::string cat(const Parts&... parts) {
    std::string out;
    (out.append(std::string_view(parts)), ...);
    return out;
}
}  // namespace

Client::Client(std::shared_ptr<serial::LineLink> link, int address) : link_(std::move(link)), address_(address) {
    if (!link_) throw InvalidArgument("toy client: a LineLink is required");
    if (address_ < 1 || address_ > 9) throw InvalidArgument(cat("toy address: 1..9, not ", std::to_string(address_)));
}

std::string Client::command(std::string_view text) {
    std::string request = cat("@", std::to_string(address_), " ");
    request.append(text);
    std::string answer = link_->transact(request);
    if (answer.rfind("ERR", 0) == 0) throw DriveFault(cat("toy ", std::to_string(address_), ": ", answer));
    return answer;
}

void Client::ok(std::string_view text) {
    std::string answer = command(text);
    if (answer != "OK") throw ProtocolError(cat("toy: '", text, "' answered '", answer, "', not OK"));
}

void Client::move_to(std::int64_t target) { ok(cat("MOVE ", std::to_string(target))); }
void Client::jog(double velocity) { ok(cat("JOG ", std::to_string(velocity))); }
void Client::stop() { ok("STOP"); }
void Client::abort() { ok("ABORT"); }
void Client::enable() { ok("ENABLE"); }
void Client::disable() { ok("DISABLE"); }
void Client::clear() { ok("CLEAR"); }
void Client::home() { ok("HOME"); }

namespace {
template <class T>
T number(const std::string& answer, const char* what) {
    T v{};
    auto r = std::from_chars(answer.data(), answer.data() + answer.size(), v);
    if (r.ec != std::errc() || r.ptr != answer.data() + answer.size())
        throw ProtocolError(cat("toy: ", what, " answered '", answer, "', not a number"));
    return v;
}
}  // namespace

std::int64_t Client::position() { return number<std::int64_t>(command("POS?"), "POS?"); }

double Client::get(const std::string& name) {
    return static_cast<double>(number<std::int64_t>(command(cat(name, "?")), name.c_str()));
}

void Client::set(const std::string& name, double value) {
    ok(cat(name, " ", std::to_string(static_cast<long long>(std::llround(value)))));
}
double Client::velocity() { return static_cast<double>(number<std::int64_t>(command("VEL?"), "VEL?")); }

Status Client::status() {
    // "<DISABLED|IDLE|MOVING|FAULT> <last stop> <HOMED|UNHOMED>"
    std::string answer = command("STATUS?");
    std::string words[3];
    std::size_t at = 0;
    for (auto& w : words) {
        std::size_t end = answer.find(' ', at);
        w = answer.substr(at, end == std::string::npos ? std::string::npos : end - at);
        at = end == std::string::npos ? answer.size() : end + 1;
    }
    const auto bad = [&] { return ProtocolError(cat("toy: STATUS? answered '", answer, "'")); };
    if (words[0] != "DISABLED" && words[0] != "IDLE" && words[0] != "MOVING" && words[0] != "FAULT") throw bad();
    if (words[2] != "HOMED" && words[2] != "UNHOMED") throw bad();
    Status st;
    st.enabled = words[0] == "IDLE" || words[0] == "MOVING";
    st.moving = words[0] == "MOVING";
    st.fault = words[0] == "FAULT";
    st.homed = words[2] == "HOMED";
    for (LastStop s : {LastStop::None, LastStop::Target, LastStop::Stop, LastStop::Abort, LastStop::Disable,
                       LastStop::Fault})
        if (words[1] == to_string(s)) {
            st.last_stop = s;
            return st;
        }
    throw bad();
}

}  // namespace motorbus::toy
