// The DMAC command language on a module: a frame's commands, run live or as
// a sequence line, and the sequence editor's storing of them.  The other half
// of dmac::Sim (time, motion, variables, inspection) is sim.cpp.
#include <memory>
#include <string>

#include "motorbus/drives/dmac/sim.hpp"
#include "motorbus/drives/dmac/sim_internal.hpp"

namespace motorbus::dmac {

using namespace sim_detail;

// ---- commands -------------------------------------------------------------------
bool Sim::in_range(std::optional<std::int32_t> v, std::int64_t lo, std::int64_t hi) {
    if (!v) return false;
    if (*v < lo || *v > hi) {
        flag(error::kLimit);
        return false;
    }
    return true;
}

std::string Sim::execute_locked(const Command& c, bool from_sequencer, bool global) {
    (void)global;
    if (!from_sequencer && sequence_only(c.cmd)) {
        flag(error::kSyntax);
        return "";
    }
    if (from_sequencer && live_only(c.cmd)) {
        flag(error::kSyntax);
        return "";
    }
    switch (c.cmd) {
        case Cmd::CloseSeq: case Cmd::OpenSeq: case Cmd::ReadSeq: case Cmd::StartSeq: case Cmd::Step:
            return sequencer_command_locked(c);
        case Cmd::Brake: case Cmd::Halt: case Cmd::Stop: case Cmd::MoveOn: case Cmd::MoveTo:
        case Cmd::MoveSpeed: case Cmd::Power: case Cmd::Synchro:
            motion_command_locked(c);
            return "";
        default:
            return setting_command_locked(c);
    }
}

// OPEN_SEQ, CLOSE_SEQ, READ_SEQ, START_SEQ, STEP.
std::string Sim::sequencer_command_locked(const Command& c) {
    switch (c.cmd) {
        case Cmd::CloseSeq:
            seq_.close_editor();
            return "";
        case Cmd::OpenSeq:
            seq_.open_editor();
            return "";
        case Cmd::ReadSeq: {
            auto n = eval(c.expr);
            if (!in_range(n, 1, kSeqLines)) return "";
            const auto& l = seq_.program_line(*n);
            return format_seq_reply(address_, *n, l ? format_command(*l) : "") + options_.reply_terminator;
        }
        case Cmd::StartSeq: {
            std::optional<std::int32_t> n = 1;
            if (c.has_arg) n = eval(c.expr);
            if (in_range(n, 1, kSeqLines)) seq_.start(*n);
            return "";
        }
        case Cmd::Step: {
            std::optional<std::int32_t> n = seq_.step_default();
            if (c.has_arg) n = eval(c.expr);
            if (!in_range(n, 1, kSeqLines)) return "";
            // Debug mode: one line now, the sequencer itself stays stopped.
            SeqHost host(*this);
            seq_.step(host, *n, now_ms_);
            return "";
        }
        default:
            flag(error::kSyntax);
            return "";
    }
}

// The commands that start, stop or power the motion; none answers.
void Sim::motion_command_locked(const Command& c) {
    switch (c.cmd) {
        case Cmd::Brake:
            if (!dmac34()) {
                flag(error::kSyntax);
                return;
            }
            brake_ = c.keyword == Keyword::On;
            if (brake_) halt_motion();
            return;
        case Cmd::Halt:
            if (c.keyword != Keyword::Seq) halt_motion();
            if (c.keyword != Keyword::Mouv) seq_.stop();
            return;
        case Cmd::Stop:
            if (c.keyword != Keyword::Seq) {
                // In interpolation STOP is HALT and empties the FIFO.
                if (interpolating_) halt_motion();
                else {
                    fifo_.clear();
                    motion_->stop(motion_t());
                    command_axis();
                }
            }
            if (c.keyword != Keyword::Mouv) seq_.stop();
            return;
        case Cmd::MoveOn:
        case Cmd::MoveTo:
        case Cmd::MoveSpeed: {
            auto v = eval(c.expr);
            if (c.cmd == Cmd::MoveSpeed && !in_range(v, -400000, 400000)) return;
            if (!v) return;
            if (synchro_) pending_ = std::make_unique<Pending>(Pending{c.cmd, *v});
            else start_move(c.cmd, *v);
            return;
        }
        case Cmd::Power:
            if (c.keyword == Keyword::On) {
                if (!(error_ & kFaultBits)) power_ = true;
            } else {
                // OFF: no current, no torque -- the rotor freewheels; SC: the
                // short-circuited coils brake it (low-speed resisting torque, 4.15).
                coast(c.keyword == Keyword::Sc ? kShortCircuitTau : kFreewheelTau);
                power_ = false;
            }
            return;
        case Cmd::Synchro:
            synchro_command_locked(c.keyword);
            return;
        default:
            flag(error::kSyntax);
            return;
    }
}

void Sim::synchro_command_locked(Keyword k) {
    switch (k) {
        case Keyword::On: synchro_ = true; break;
        case Keyword::Off:
            synchro_ = false;
            pending_.reset();
            break;
        case Keyword::Top:
            if (pending_) {
                Pending p = *pending_;
                pending_.reset();
                start_move(p.kind, p.value);
            }
            break;
        case Keyword::Interpol:
            if (!fifo_.empty() && !interpolating_) {
                // Any other motion stops at once; the FIFO takes over.
                axis_->halt();
                restart_motion_at(user_position());
                interpolating_ = true;
                start_interp_segment();
                power_ = true;
                abnormal_stop_ = false;
            }
            break;
        default: break;
    }
}

// Variables, settings, READ, MOVE_INTERPOL and the module's own commands.
std::string Sim::setting_command_locked(const Command& c) {
    const std::string& term = options_.reply_terminator;
    switch (c.cmd) {
        case Cmd::Invalid:
            flag(c.error_bit ? c.error_bit : error::kSyntax);
            return "";
        case Cmd::Assign: {
            auto v = eval(c.expr);
            if (!v) return "";
            if (int e = write_var_locked(c.var, c.bit, *v)) flag(e);
            return "";
        }
        case Cmd::HardEnds:
            hard_pos_ = c.keyword == Keyword::All || c.keyword == Keyword::Pos;
            hard_neg_ = c.keyword == Keyword::All || c.keyword == Keyword::Neg;
            return "";
        case Cmd::InversePolarity:
            invert_in_ = c.keyword == Keyword::All || c.keyword == Keyword::In;
            invert_out_ = c.keyword == Keyword::All || c.keyword == Keyword::Out;
            return "";
        case Cmd::ModuleReset:
            reset_locked(c.keyword == Keyword::All);
            return "";
        case Cmd::MoveInterpol: {
            auto v = eval(c.expr);
            if (!v) return "";
            const auto cap = static_cast<std::size_t>(vars_[static_cast<std::size_t>(Var::InterpolFifosize)]);
            if (fifo_.size() >= cap) return std::string(1, kXonError);
            fifo_.push_back({*v, vars_[static_cast<std::size_t>(Var::InterpolTime)]});
            return "";
        }
        case Cmd::Nop:
            return "";
        case Cmd::OptimizedCurrent:
            optimized_current_ = c.keyword == Keyword::On;
            return "";
        case Cmd::SCurve:
            s_curve_ = c.keyword == Keyword::On;
            return "";
        case Cmd::SoftEnds:
            soft_ends_ = c.keyword == Keyword::On;
            return "";
        case Cmd::Read: {
            auto v = read_var_locked(c.var, c.bit);
            if (!v) {
                flag(error::kSyntax);
                return "";
            }
            return format_read_reply(address_, c.var, c.bit, *v, c.radix) + term;
        }
        case Cmd::Reference:
            reference_ = c.keyword == Keyword::On;
            return "";
        case Cmd::RequestVersion: {
            std::string code = dmac34() ? "H142" : (options_.model == Model::Dmac17 ? "9148" : "F138");
            return address_prefix(address_) + "EV " + options_.firmware + " " + code +
                   " \"MIDI-INGENIERIE_" + std::string(model_name(options_.model)) + "_" +
                   options_.serial_number + "_" + options_.manufacturing_date + "_" +
                   options_.revision_date + "\" PHASE:" + options_.phase + " BOOT:" + options_.boot +
                   term;
        }
        case Cmd::SetAddress: {
            auto n = eval(c.expr);
            if (in_range(n, 0, kMaxAddress)) address_ = *n;
            return "";
        }
        case Cmd::SetBaudrate: {
            auto n = eval(c.expr);
            if (!n) return "";
            if (*n != 9600 && *n != 19200 && *n != 38400 && *n != 115200) flag(error::kLimit);
            else baudrate_ = *n;
            return "";
        }
        default:
            flag(error::kSyntax);
            return "";
    }
}

std::string Sim::handle_locked(std::string_view line) {
    ++lines_handled_;
    Request req = parse_request(line);
    if (req.address_error) return "";
    const bool global = req.address == kGlobal;
    if (!global && req.address != address_) return "";
    bool rejected = false;
    std::string reply;
    if (seq_.editing()) {
        int at = req.seq_line ? req.seq_line : seq_.edit_line();
        for (const Command& c : req.commands) {
            if (c.cmd == Cmd::Invalid) {
                flag(c.error_bit);
                rejected = true;
            } else if (live_only(c.cmd)) {
                reply += execute_locked(c, false, global);
            } else if (!seq_.store(at, c)) {
                flag(error::kLimit);
                rejected = true;
            } else {
                ++at;
            }
        }
    } else {
        if (req.seq_line) {
            flag(error::kSyntax);  // ":n" only means something while editing
            rejected = true;
        } else {
            for (const Command& c : req.commands)
                if (c.cmd == Cmd::Invalid) {
                    // A frame with a syntax error changes nothing (half a frame
                    // could start a move the host never meant); its READs still
                    // answer, so "cmd, READ #ERROR" reports the rejection.
                    flag(c.error_bit);
                    rejected = true;
                }
            for (const Command& c : req.commands)
                if (!rejected || c.cmd == Cmd::Read) reply += execute_locked(c, false, global);
        }
    }
    if (rejected) ++lines_rejected_;
    // Global frames run everywhere but only module 00 answers them.
    if (global && address_ != 0) return "";
    return reply;
}

}  // namespace motorbus::dmac
