// The DMAC's sequencer (manual 5.9, 5.10): a 500-line stored program, its
// editor (OPEN_SEQ ... CLOSE_SEQ, ":n" line numbers), and the interpreter that
// runs one line per millisecond with JUMP/JUMPR/CALL/RETURN (five nested calls),
// IF and WAIT (time, end of motion, end of motion with a timeout).
//
// The module it belongs to (dmac::Sim) owns everything else: a line's other
// commands, expressions and the error bits are reached through Host.  The
// sequencer holds no lock; the module calls it with its own held.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "motorbus/drives/dmac/codec.hpp"

namespace motorbus::dmac {

class Sequencer {
public:
    // What the sequencer asks of its module.
    struct Host {
        virtual std::optional<std::int32_t> eval(const Expr& e) = 0;  // nullopt: error already flagged
        virtual void flag(int error_bit) = 0;
        virtual void execute(const Command& c) = 0;  // any command but flow control, as a sequence line
        virtual bool moving() = 0;                   // WAIT 0 / WAIT -t wait for this to end
    protected:
        ~Host() = default;
    };

    Sequencer();

    // ---- the program --------------------------------------------------------
    const std::optional<Command>& program_line(int n) const;  // n in 1..kSeqLines
    void open_editor();   // OPEN_SEQ: stops, erases the program, edits from line 1
    void close_editor() { editing_ = false; }
    bool editing() const { return editing_; }
    int edit_line() const { return edit_line_; }  // where a line without ":n" goes
    // Stores `c` at line `at`, the next line to edit becoming at + 1; false
    // (nothing stored) past kSeqLines.
    bool store(int at, const Command& c);

    // ---- running -------------------------------------------------------------
    bool running() const { return running_; }
    int line() const { return running_ ? line_ : 0; }  // #LINE
    void start(int line);
    void stop();
    void set_line(int line) { line_ = line; }  // #LINE := n (n > 0)
    // One millisecond at `now_ms`: the current line runs unless a WAIT holds it.
    void tick(Host& host, std::int64_t now_ms);
    // STEP [n]: line n (by default the current line, else 1) runs now; the
    // sequencer itself stays stopped.
    int step_default() const { return line_ ? line_ : 1; }
    void step(Host& host, int n, std::int64_t now_ms);
    void reset();  // MODULE_RESET: not editing, not running (the program stays)

private:
    void execute_line(Host& host, int n, std::int64_t now_ms);
    // JUMP/JUMPR/CALL from line n to `target`: the next line in `next`.
    bool jump_to(Host& host, int n, Cmd kind, const Expr& target, int& next);

    std::vector<std::optional<Command>> program_;  // index 1..kSeqLines
    bool editing_ = false;
    int edit_line_ = 1;
    bool running_ = false;
    int line_ = 0;  // next line to execute (0 = stopped)
    std::vector<int> call_stack_;
    enum class WaitKind { None, Time, Motion, MotionTimeout } wait_ = WaitKind::None;
    std::int64_t wait_until_ms_ = 0;
    int resume_line_ = 0;  // line after the WAIT in progress
};

}  // namespace motorbus::dmac
