// A mutex that hands itself over in the order threads asked for it.
//
// std::mutex lets the thread that has just unlocked take it again at once, so a
// loop of critical sections with nothing in between — a poller reading a slow
// line back to back, always behind its deadlines — can keep another thread out
// for as long as it runs (a user's command waited 0.9 s behind a 1 kHz poll
// of a serial drive).  Here each waiter takes a ticket and is served in turn, so a waiter
// waits for at most the holders that came before it.  BasicLockable: use it
// with std::lock_guard / std::unique_lock.  Not recursive.
#pragma once
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace motorbus {

class FifoMutex {
public:
    void lock() {
        std::unique_lock lk(m_);
        const std::uint64_t ticket = next_ticket_++;
        cv_.wait(lk, [&] { return serving_ == ticket; });
    }
    void unlock() {
        {
            std::lock_guard lk(m_);
            ++serving_;
        }
        cv_.notify_all();  // every waiter checks whether its ticket is next
    }

private:
    std::mutex m_;
    std::condition_variable cv_;
    std::uint64_t next_ticket_ = 0;
    std::uint64_t serving_ = 0;
};

}  // namespace motorbus
