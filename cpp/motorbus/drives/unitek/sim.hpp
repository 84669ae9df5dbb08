// A simulated UNITEK BAMOCAR/BAMOBIL/DS servo on the register protocol (002 manual).
//
// The drive listens on its receive id (0x201) and answers on its transmit id
// (0x181).  Writes are never acknowledged (B-U05).  `3D <REGID> <t>` reads a
// register once (t = 0), every t ms (1..254, at most 8 registers, a repeated
// request replaces the period, the first frame goes out at once) or stops it
// (0xFF).  With MODE bit 4 set, KERN_STATUS is sent (DLC 6) whenever a status
// bit selected by the event mask (0x52) changes.  The motion runs on a
// motion::MotorModel on the sim's Clock: speed control with the ACC ramp,
// position control to POS_DEST (Tol = in the position window), a torque
// command (no load: the rotor accelerates to N max at a rate proportional to
// the torque), enable by MODE bit 2 and a hardware enable input, limit
// switches, the calibration bit and the continuous current limit (Icns).
// EEPROM (0x84) keeps every writable register over power_cycle() (B-U13).
// The current registers of NDrive's list (I_CMD 0x26, I_ACT 0x20, I_MAX 0x24,
// DEVICE_I_MAX 0xC4) model §6.1's table: a current command of +/- 9 bit, the
// delivered current limited by the smaller of the motor and device limits.
// The node talks at its BTR's bit rate (§3.1 table): on a bus modelling
// another bit rate it neither hears nor sends anything.
//
// Time: the sim is evaluated when a frame arrives and by a timer thread; on a
// SimClock a test calls service() after advancing the clock to get every frame
// due by then, in time order, before it returns.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/can/sim_device.hpp"
#include "motorbus/drives/unitek/codec.hpp"
#include "motorbus/drives/unitek/profile.hpp"
#include "motorbus/motion/motor_model.hpp"
#include "motorbus/runtime/clock.hpp"
#include "motorbus/runtime/timer_thread.hpp"

namespace motorbus::unitek {

struct SimConfig {
    std::uint32_t rx_id = kDefaultRxId;
    std::uint32_t tx_id = kDefaultTxId;
    double n_max_rpm = 3000;         // N max: 32767 num
    double acc_ramp_ms = 1000;       // 0x35 at the factory
    double dec_ramp_ms = 1000;       // NDrive's deceleration ramp (not on this manual's bus)
    bool position_control = true;    // KERN_STATUS bit 7 (B-U23: an NDrive setting)
    bool speed_control = true;       // KERN_STATUS bit 8
    bool calibrated = false;         // Cal (bit 12); ex 8 reads 0x0181: not calibrated
    std::int64_t tol_num = 64;       // position window of Tol (num)
    std::optional<double> minus_limit_num = -100.0 * 65536;  // limit switch positions (num); nullopt = none
    std::optional<double> plus_limit_num = 100.0 * 65536;
    std::int64_t torque_continuous_num = 32767;  // |torque| above this: Icns (continuous current limit)
    std::uint8_t dummy = 0x00;       // the reply's dummy byte (B-U04: unspecified, 0x00)
    std::string device = "DS 205/405";             // §6.1 current table row
    std::optional<std::int64_t> motor_i_max_num;   // the motor's peak current limit (num); nullopt = the device's
    std::uint16_t btr = kDefaultBtr;               // NDrive CAN-Setup NBT (§3.1): not changeable over CAN (B-U21)
    int analog_command = 0;  // the speed command's source (an NDrive setting): 0 = the bus, 1 = AIN1, 2 = AIN2
    void validate() const;           // InvalidArgument naming the field
};

struct SimCounters {
    std::uint64_t frames_in = 0;       // frames on the receive id
    std::uint64_t ignored = 0;         // other ids, RTR, extended ids
    std::uint64_t malformed = 0;       // DLC < 3
    std::uint64_t unknown = 0;         // unknown REGID (write or read)
    std::uint64_t refused = 0;         // write to a read-only register / value out of range
    std::uint64_t cyclic_refused = 0;  // a 9th cyclic register
    std::uint64_t frames_out = 0;
    std::uint64_t events_out = 0;
    // Frames on a bus of another bit rate: not decoded (error frames) or not heard (its own), counted
    // by the bit-rate gate it attaches through, over every attachment.
    std::uint64_t bit_rate_mismatch = 0;
};

// The sim's registers: the documented ones plus POS_IST (0x6D, actual position, 32-bit signed, read-only).
RegisterTable sim_default_table();

class Sim : public can::SimulatedDevice {
public:
    Sim(Clock& clock, SimConfig cfg = {}, RegisterTable table = sim_default_table());
    // Shares ownership of the clock (bindings, servers that outlive the caller).
    Sim(std::shared_ptr<Clock> clock, SimConfig cfg = {}, RegisterTable table = sim_default_table());
    ~Sim();
    Sim(const Sim&) = delete;
    Sim& operator=(const Sim&) = delete;

    // ---- can::SimulatedDevice ----
    // Serve on `bus` (kept alive until close()) through a gate at its BTR's bit
    // rate: subscribes to every standard id, starts the timer thread.
    void attach(std::shared_ptr<can::Bus> bus) override;
    void close() override;
    bool attached() const override;
    std::string describe() const override;  // "unitek sim tx 0x181"
    double node_bit_rate() const override { return bit_rate(); }
    // Output without a bus (fuzzing, unit tests): every frame the drive sends.
    void set_output(std::function<void(const can::Frame&)> out);

    // A frame seen on the bus (public for tests and fuzzing; not id-filtered by the caller).
    void on_frame(const can::Frame& f);
    // Emits every cyclic / event frame due by clock.now(); returns the next due time (-1: none).
    Nanos service();

    // ---- sim inputs ----
    void set_hardware_enable(bool on);
    void force_limit(int direction, std::optional<bool> active);  // +1 / -1; nullopt: follow the position
    void set_calibrated(bool on);
    void force_icns(std::optional<bool> active);
    // NDrive's error/warning register (0x8F): set bits latch.  An error bit (0-15)
    // switches the power stage off (Ena 0, the rotor stops where it is) until a
    // MODE write that enables the drive clears the errors (this sim's reading: how
    // NDrive clears an error is not in 002).  Warning bits (16-31) only show.
    void force_error(std::uint32_t bits);
    // The voltage on AIN1/AIN2 (+/- 10 V): reads as 2949 num/V (0xD5/0xD6); with
    // analog_command = that input, it is the speed command (10 V = 29490 = 90 % N max).
    void set_analog_input(int channel, double volts);
    void power_cycle() override;  // EEPROM values back, RAM values lost, cyclic/events off, motor stopped

    // ---- introspection ----
    std::uint32_t status();
    std::int64_t value(std::uint8_t regid);   // the register as a read would return it; UnknownRegister
    double position_num();
    double speed_num();
    double bit_rate() const;         // of its BTR, bit/s
    double bus_bit_rate() const;     // of the bus attached (0: none modelled)
    std::uint32_t rx_id() const;
    std::uint32_t tx_id() const { return cfg_.tx_id; }
    std::vector<std::pair<std::uint8_t, int>> cyclic() const;  // (REGID, period ms)
    std::uint64_t sent(std::uint8_t regid) const;               // frames sent for REGID
    SimCounters counters() const;
    const SimConfig& config() const { return cfg_; }
    std::map<std::uint8_t, std::int64_t> eeprom() const;
    void load_eeprom(const std::map<std::uint8_t, std::int64_t>& values);  // a stored file, before use
    // Called (outside the sim's lock, on the thread that handled 0x84) with the
    // EEPROM contents after each store: lets a host keep them in a file.
    void on_eeprom_store(std::function<void(const std::map<std::uint8_t, std::int64_t>&)> cb);

private:
    struct Slot {
        std::uint8_t regid;
        Nanos period;
        Nanos next;
    };
    enum class Activity { Idle, Speed, Position, Torque };

    std::vector<can::Frame> advance_locked(Nanos now);  // cyclic + events up to now, motor to now
    void emit_reply_locked(std::uint8_t regid, std::vector<can::Frame>& out);
    void check_events_locked(std::vector<can::Frame>& out);
    void handle_locked(const ToDrive& t, std::vector<can::Frame>& out);
    void write_locked(std::uint8_t regid, std::uint32_t raw, int bits);
    void apply_enable_locked();
    void limits_locked();
    void speed_locked(double num, double ramp_scale);
    std::uint32_t status_locked();
    std::int64_t value_locked(std::uint8_t regid);
    motion::State state_locked();
    RampParams ramps_locked() const;
    void send(const std::vector<can::Frame>& frames);
    void reset_ram_locked();
    std::int64_t current_limit_locked() const;

    Clock& clock_;
    SimConfig cfg_;
    RegisterTable table_;
    mutable std::mutex m_;
    motion::MotorModel motor_;
    std::map<std::uint8_t, std::int64_t> regs_;    // RAM values of the table's registers
    std::map<std::uint8_t, std::int64_t> eeprom_;  // stored by 0x84
    std::vector<Slot> slots_;
    std::map<std::uint8_t, std::uint64_t> sent_;
    std::uint32_t rx_id_;
    std::uint16_t mode_ = 0;
    bool hw_enable_ = true;
    bool calibrated_;
    std::optional<bool> icns_forced_;
    std::uint32_t err_warn_ = 0;  // 0x8F
    std::int64_t ain_[2] = {0, 0};  // num
    void analog_speed_locked();
    std::optional<bool> limit_forced_[2];  // [0] minus, [1] plus
    Activity activity_ = Activity::Idle;
    std::uint32_t last_status_ = 0;
    SimCounters counters_;

    std::function<void(const can::Frame&)> out_;
    std::function<void(const std::map<std::uint8_t, std::int64_t>&)> eeprom_cb_;
    bool eeprom_dirty_ = false;
    std::shared_ptr<can::BitRateGate> gate_;  // on the medium attach() was given, which it keeps alive
    std::uint64_t refused_before_ = 0;       // the gates of earlier attachments refused this many
    std::shared_ptr<Clock> clock_owner_;     // set by the shared_ptr constructor
    can::SubscriptionId sub_ = 0;
    std::unique_ptr<TimerThread> timer_;
};

}  // namespace motorbus::unitek
