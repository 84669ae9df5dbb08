// A tiny in-process bus for the canopen tests: every endpoint has its own
// receive thread (like a real backend) and sees the frames the others send.
// A tap records every frame in send order, and a drop filter injects losses.
#pragma once
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "motorbus/can/bus.hpp"
#include "motorbus/errors.hpp"

namespace motorbus::test {

class LoopHub;

class LoopBus final : public can::Bus {
public:
    LoopBus(std::shared_ptr<LoopHub> hub, std::string name);
    ~LoopBus() override { close(); }
    void deliver(const can::Frame& f) {
        {
            std::lock_guard l(m_);
            q_.push_back(f);
        }
        cv_.notify_one();
    }

protected:
    void do_send(const can::Frame& frame, can::Deadline deadline) override;
    void do_close() override;
    void do_close_impl() {
        {
            std::lock_guard l(m_);
            stop_ = true;
        }
        cv_.notify_all();
        if (t_.joinable()) t_.join();
    }

private:
    void run() {
        std::unique_lock l(m_);
        while (true) {
            cv_.wait(l, [&] { return stop_ || !q_.empty(); });
            if (stop_) return;
            auto f = q_.front();
            q_.pop_front();
            l.unlock();
            dispatch(f);
            l.lock();
        }
    }
    std::shared_ptr<LoopHub> hub_;
    std::mutex m_;
    std::condition_variable cv_;
    std::deque<can::Frame> q_;
    bool stop_ = false;
    std::thread t_;
};

class LoopHub : public std::enable_shared_from_this<LoopHub> {
public:
    std::shared_ptr<LoopBus> open(std::string name = "loop") {
        auto b = std::make_shared<LoopBus>(shared_from_this(), std::move(name));
        std::lock_guard l(m_);
        buses_.push_back(b.get());
        return b;
    }
    void leave(LoopBus* b) {
        std::lock_guard l(m_);
        std::erase(buses_, b);
    }
    void send(LoopBus* from, const can::Frame& f) {
        std::lock_guard l(m_);
        if (drop && drop(f)) return;
        tap.push_back(f);
        for (auto* b : buses_)
            if (b != from) b->deliver(f);
    }
    std::vector<can::Frame> frames() {
        std::lock_guard l(m_);
        return tap;
    }
    void clear() {
        std::lock_guard l(m_);
        tap.clear();
    }
    std::function<bool(const can::Frame&)> drop;  // set before traffic starts
    std::vector<can::Frame> tap;

private:
    std::mutex m_;
    std::vector<LoopBus*> buses_;
};

inline LoopBus::LoopBus(std::shared_ptr<LoopHub> hub, std::string name)
    : Bus(std::move(name)), hub_(std::move(hub)) {
    t_ = std::thread([this] { run(); });
}

inline void LoopBus::do_close() {
    hub_->leave(this);
    do_close_impl();
}

inline void LoopBus::do_send(const can::Frame& frame, can::Deadline) {
    can::Frame f = frame;
    f.timestamp_ns = monotonic_ns();
    hub_->send(this, f);
}

}  // namespace motorbus::test
