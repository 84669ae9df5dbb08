// The DMX-CAN's CANopen object dictionary (manual 000 Table 10.1, the table the
// simulator serves: canopen_objects() in sim.hpp) as a typed canopen::ObjectDictionary:
// what a host reads and writes the drive by (each entry's type, access, limits and
// codec) and what the shipped EDS (canopen.eds) is generated from.
#pragma once
#include <memory>

#include "motorbus/canopen/od.hpp"

namespace motorbus::arcus {

// Every row of Table 10.1: records for the sub-indexed objects (their sub 0 is the
// dictionary's own "Highest sub-index supported"), limits on the writable rows,
// factory defaults ("DMC" for 1008h).
std::shared_ptr<canopen::ObjectDictionary> canopen_object_dictionary();

}  // namespace motorbus::arcus
