// Internal header of the DMAC simulator, shared by sim.cpp (time, motion,
// variables, inspection) and sim_commands.cpp (the command language): what
// both halves of dmac::Sim name.  Not installed API.
#pragma once
#include <cstdint>
#include <optional>

#include "motorbus/drives/dmac/codec.hpp"
#include "motorbus/drives/dmac/sim.hpp"

namespace motorbus::dmac {

struct Sim::Pending {
    Cmd kind;
    std::int32_t value;
};

// The sequencer (sequencer.cpp) runs its flow control itself and hands the
// other commands of a line back to the module.
struct Sim::SeqHost final : Sequencer::Host {
    Sim& sim;
    explicit SeqHost(Sim& s) : sim(s) {}
    std::optional<std::int32_t> eval(const Expr& e) override { return sim.eval(e); }
    void flag(int error_bit) override { sim.flag(error_bit); }
    void execute(const Command& c) override { sim.execute_locked(c, true, false); }
    bool moving() override { return sim.moving_locked(); }
};

namespace sim_detail {

// Run-down of a rotor whose power stage is off, as an exponential decay of
// speed (the manual gives no figures; these are the simulator's): POWER SC
// short-circuits the coils, whose braking torque stops it within tens of ms;
// POWER OFF leaves only friction, so it coasts ten times longer.
inline constexpr double kShortCircuitTau = 0.02;  // s
inline constexpr double kFreewheelTau = 0.2;      // s
// Hardware faults latched in #ERROR (manual 5.5); OUT2 FAULT reflects them.
inline constexpr std::uint32_t kFaultBits = bit_mask(error::kThermal) | bit_mask(error::kShortCircuit) |
                                            bit_mask(error::kUndervoltage) | bit_mask(error::kOvervoltage);

// Live-only commands run at once even while a sequence is being edited and
// are never stored; sequence-only commands are refused in live mode.
inline bool live_only(Cmd c) {
    switch (c) {
        case Cmd::Read: case Cmd::ReadSeq: case Cmd::OpenSeq: case Cmd::CloseSeq:
        case Cmd::RequestVersion: case Cmd::SetAddress: case Cmd::SetBaudrate:
        case Cmd::ModuleReset: case Cmd::Step: case Cmd::Invalid:
            return true;
        default:
            return false;
    }
}
inline bool sequence_only(Cmd c) {
    switch (c) {
        case Cmd::Call: case Cmd::Return: case Cmd::If: case Cmd::Jump: case Cmd::JumpRel:
        case Cmd::Wait:
            return true;
        default:
            return false;
    }
}

}  // namespace sim_detail

}  // namespace motorbus::dmac
