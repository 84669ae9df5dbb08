#include "motorbus/drives/dmac/sequencer.hpp"

namespace motorbus::dmac {

Sequencer::Sequencer() : program_(kSeqLines + 1) {}

const std::optional<Command>& Sequencer::program_line(int n) const {
    return program_.at(static_cast<std::size_t>(n));
}

void Sequencer::open_editor() {
    stop();
    for (auto& l : program_) l.reset();
    editing_ = true;
    edit_line_ = 1;
}

bool Sequencer::store(int at, const Command& c) {
    if (at > kSeqLines) return false;
    program_[static_cast<std::size_t>(at)] = c;
    edit_line_ = at + 1;
    return true;
}

void Sequencer::start(int line) {
    running_ = true;
    line_ = line;
    call_stack_.clear();
    wait_ = WaitKind::None;
}

void Sequencer::stop() {
    running_ = false;
    line_ = 0;
    call_stack_.clear();
    wait_ = WaitKind::None;
}

void Sequencer::reset() {
    editing_ = false;
    stop();
}

void Sequencer::tick(Host& host, std::int64_t now_ms) {
    if (!running_) return;
    switch (wait_) {
        case WaitKind::Time:
            if (now_ms < wait_until_ms_) return;
            break;
        case WaitKind::Motion:
            if (host.moving()) return;
            break;
        case WaitKind::MotionTimeout:
            if (host.moving() && now_ms < wait_until_ms_) return;
            break;
        case WaitKind::None:
            break;
    }
    if (wait_ != WaitKind::None) {
        wait_ = WaitKind::None;
        line_ = resume_line_;
        if (line_ < 1 || line_ > kSeqLines) {
            stop();
            return;
        }
    }
    execute_line(host, line_, now_ms);
}

void Sequencer::step(Host& host, int n, std::int64_t now_ms) {
    running_ = true;
    execute_line(host, n, now_ms);
    const int next = wait_ != WaitKind::None ? resume_line_ : line_;
    running_ = false;
    wait_ = WaitKind::None;
    line_ = next;
}

bool Sequencer::jump_to(Host& host, int n, Cmd kind, const Expr& target, int& next) {
    auto t = host.eval(target);
    if (!t) return false;
    std::int64_t dest = *t;
    if (kind == Cmd::JumpRel) dest = n + static_cast<std::int64_t>(*t);
    if (kind == Cmd::Jump && dest == 0) {  // JUMP 0 ends the program
        next = 0;
        return true;
    }
    if (dest < 1 || dest > kSeqLines) {
        host.flag(error::kLimit);
        return false;
    }
    if (kind == Cmd::Call) {
        if (call_stack_.size() >= 5) {  // five nested calls at most
            host.flag(error::kLimit);
            return false;
        }
        call_stack_.push_back(n + 1);
    }
    next = static_cast<int>(dest);
    return true;
}

void Sequencer::execute_line(Host& host, int n, std::int64_t now_ms) {
    if (n < 1 || n > kSeqLines) {
        stop();
        return;
    }
    line_ = n;
    int next = n + 1;
    const std::optional<Command>& slot = program_[static_cast<std::size_t>(n)];
    bool ok = true;
    if (slot) {
        const Command& c = *slot;
        switch (c.cmd) {
            case Cmd::Jump: case Cmd::JumpRel: case Cmd::Call:
                ok = jump_to(host, n, c.cmd, c.expr, next);
                break;
            case Cmd::Return:
                if (call_stack_.empty()) {
                    host.flag(error::kSyntax);
                    ok = false;
                } else {
                    next = call_stack_.back();
                    call_stack_.pop_back();
                }
                break;
            case Cmd::If: {
                auto t = host.eval(c.expr);
                if (!t) ok = false;
                else if (*t != 0) ok = jump_to(host, n, c.jump, c.target, next);
                break;
            }
            case Cmd::Wait: {
                auto w = host.eval(c.expr);
                if (!w || *w < -3600000 || *w > 3600000) {
                    if (w) host.flag(error::kLimit);
                    ok = false;
                } else if (*w > 0) {
                    wait_ = WaitKind::Time;
                    wait_until_ms_ = now_ms + *w;
                } else if (*w == 0) {
                    wait_ = WaitKind::Motion;
                } else {
                    wait_ = WaitKind::MotionTimeout;
                    wait_until_ms_ = now_ms - static_cast<std::int64_t>(*w);
                }
                break;
            }
            default:
                host.execute(c);
                break;
        }
    }
    // A failed flow-control line stops the program (the error bit says why).
    if (!ok) {
        stop();
        return;
    }
    if (!running_) return;  // the line itself stopped the sequencer (STOP, HALT, #LINE:=0)
    if (line_ != n) return;  // the line wrote #LINE: that is the next line
    if (wait_ != WaitKind::None) {
        resume_line_ = next;  // #LINE shows the WAIT line while it waits
        return;
    }
    if (next < 1 || next > kSeqLines) stop();
    else line_ = next;
}

}  // namespace motorbus::dmac
