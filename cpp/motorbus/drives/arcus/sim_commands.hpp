// The DMX-CAN firmware's commands on the simulator's state: one handler per
// command and form, hung from the codec's command table (codec.hpp).  Internal
// header of the arcus folder, used by sim.cpp.
#pragma once
#include <string>
#include <string_view>

#include "motorbus/drives/arcus/codec.hpp"
#include "motorbus/drives/arcus/sim_core.hpp"

namespace motorbus::arcus::sim_detail {

// Runs a parsed command whose index and busy checks have passed; returns the
// reply body.  `raw` is the command as received (echoed in "?<command>").
// The motor has been advanced to `now`.  mutex_ held.
std::string run_command(State& s, const SimOptions& options, Nanos now, const ParsedCommand& pc,
                        std::string_view raw);

// "?<command>" echoing what came (a bare "?" for a command too long or not
// printable): the reply to a command the firmware does not take.
std::string unknown_reply(std::string_view raw);

// STORE's write of the flash to `path` (nothing when empty); atomic by rename.
void save_flash(const std::string& path, Flash f);

}  // namespace motorbus::arcus::sim_detail
