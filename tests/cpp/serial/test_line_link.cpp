// LineLink over a real pty with a scripted C++ peer on the slave side.
// Hostile rows covered at the link level: A1, A3, A8, A10, A11.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <set>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "motorbus/serial/port.hpp"

using namespace motorbus;
using namespace motorbus::serial;
using namespace std::chrono_literals;

namespace {
std::span<const std::uint8_t> as_bytes(const std::string& s) {
    return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// The device side: reads requests ending in CR and answers with scripted chunks.
struct Chunk {
    std::string bytes;
    Duration delay_before{};
};

class ScriptedPeer {
public:
    using Script = std::function<std::vector<Chunk>(const std::string& request)>;
    ScriptedPeer(PtyPair& pty, Script script, bool echo = false)
        : port_(pty.open_slave()), script_(std::move(script)), echo_(echo), thread_([this] { run(); }) {}
    ~ScriptedPeer() {
        port_->close();
        thread_.join();
    }
    std::vector<std::string> requests() {
        std::lock_guard lk(m_);
        return requests_;
    }
    Port& port() { return *port_; }
    // Blocks until the peer has written every chunk of `n` replies, then lets
    // the pty hand the bytes over (deterministic "the late tail has landed").
    void wait_replies(int n) {
        while (done_.load() < n) std::this_thread::sleep_for(1ms);
        std::this_thread::sleep_for(20ms);
    }

private:
    void run() {
        std::string line;
        std::uint8_t buf[256];
        try {
            for (;;) {
                std::size_t n = port_->read(buf, Duration(-1));
                for (std::size_t i = 0; i < n; ++i) {
                    char ch = static_cast<char>(buf[i]);
                    line.push_back(ch);
                    if (ch != '\r') continue;
                    if (echo_) port_->write(as_bytes(line));
                    std::string req = line.substr(0, line.size() - 1);
                    line.clear();
                    {
                        std::lock_guard lk(m_);
                        requests_.push_back(req);
                    }
                    for (auto& c : script_(req)) {
                        if (c.delay_before > Duration::zero()) std::this_thread::sleep_for(c.delay_before);
                        port_->write(as_bytes(c.bytes));
                    }
                    ++done_;
                }
            }
        } catch (const ClosedError&) {
        }
    }
    std::shared_ptr<TtyPort> port_;
    Script script_;
    bool echo_;
    std::mutex m_;
    std::vector<std::string> requests_;
    std::atomic<int> done_{0};
    std::thread thread_;
};

LineOptions opts(std::vector<std::string> terms = {"\r\n"}, std::size_t max_line = 64, Duration timeout = 300ms) {
    LineOptions o;
    o.reply_terminators = std::move(terms);
    o.max_line = max_line;
    o.reply_timeout = timeout;
    return o;
}
}  // namespace

TEST(LineLink, RequestBytesAndReplySplitAcrossReads) {
    PtyPair pty;
    ScriptedPeer peer(pty, [](const std::string&) {
        return std::vector<Chunk>{{"1"}, {"2", 5ms}, {"3\r", 5ms}, {"\n", 5ms}};
    });
    LineLink link(pty.port(), opts());
    EXPECT_EQ(link.transact("1PX"), "123");
    EXPECT_EQ(peer.requests(), std::vector<std::string>{"1PX"});
    auto c = link.counters();
    EXPECT_EQ(c.bytes_out, 4u);
    EXPECT_EQ(c.bytes_in, 5u);
    EXPECT_EQ(c.requests, 1u);
    EXPECT_EQ(c.replies, 1u);
}

TEST(LineLink, A1_NoTerminatorTimesOutAndPartialIsDiscarded) {
    PtyPair pty;
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string& req) {
        if (n++ == 0) return std::vector<Chunk>{{"12"}};  // terminator never comes
        return std::vector<Chunk>{{"ok:" + req + "\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 50ms));
    EXPECT_THROW(link.transact("A"), TimeoutError);
    EXPECT_EQ(link.counters().timeouts, 1u);
    // The partial "12" must not prefix the next reply.
    EXPECT_EQ(link.transact("B"), "ok:B");
}

TEST(LineLink, A1_LateTailIsFlushedBeforeNextRequest) {
    PtyPair pty;
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string& req) {
        if (n++ == 0) return std::vector<Chunk>{{"12"}, {"34\r\n", 80ms}};  // tail after the timeout
        return std::vector<Chunk>{{"ok:" + req + "\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 30ms));
    EXPECT_THROW(link.transact("A"), TimeoutError);
    peer.wait_replies(1);  // the tail is in our input queue now
    EXPECT_EQ(link.transact("B"), "ok:B");
    EXPECT_EQ(link.counters().stale_bytes, 4u);  // "34\r\n"
}

TEST(LineLink, A8_LateReplyAfterTimeoutIsDiscarded) {
    PtyPair pty;
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string& req) {
        if (n++ == 0) return std::vector<Chunk>{{"late:" + req + "\r\n", 80ms}};
        return std::vector<Chunk>{{"ok:" + req + "\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 30ms));
    EXPECT_THROW(link.transact("A"), TimeoutError);
    peer.wait_replies(1);
    EXPECT_EQ(link.transact("B"), "ok:B");
    EXPECT_EQ(link.counters().stale_bytes, 8u);  // "late:A\r\n"
}

static_assert(std::is_base_of_v<ProtocolError, ReplyTooLong>, "ReplyTooLong must be catchable as ProtocolError");

TEST(LineLink, A3_OverlongReplyIsReplyTooLongThenNextWorks) {
    PtyPair pty;
    ScriptedPeer peer(pty, [&](const std::string& req) {
        if (req == "LONG") return std::vector<Chunk>{{std::string(100, 'x')}, {std::string(100, 'y') + "\r\n", 5ms}};
        if (req == "EXACT") return std::vector<Chunk>{{std::string(16, 'e') + "\r\n"}};
        return std::vector<Chunk>{{"ok\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 16));
    try {
        link.transact("LONG");
        FAIL() << "no ReplyTooLong";
    } catch (const ReplyTooLong& e) {
        EXPECT_NE(std::string(e.what()).find("ReplyTooLong"), std::string::npos);
        EXPECT_EQ(e.bytes, std::vector<std::uint8_t>(32, 'x'));
    }
    EXPECT_EQ(link.counters().overlong_lines, 1u);
    EXPECT_EQ(link.transact("EXACT"), std::string(16, 'e'));
    EXPECT_EQ(link.transact("X"), "ok");
}

TEST(LineLink, A3_OverlongWithoutTerminatorIsReplyTooLong) {
    PtyPair pty;
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string&) {
        if (n++ == 0) return std::vector<Chunk>{{std::string(500, 'z')}};
        return std::vector<Chunk>{{"ok\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 16, 50ms));
    EXPECT_THROW(link.transact("A"), ReplyTooLong);
    EXPECT_EQ(link.transact("B"), "ok");
}

TEST(LineLink, A10_NoiseBurstsNeverCrashAndResync) {
    PtyPair pty;
    std::string noise = std::string(300, '\xff') + std::string(300, '\0');
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string&) {
        switch (n++) {
            case 0: return std::vector<Chunk>{{noise + "\r\n"}};            // a whole line of noise
            case 1: return std::vector<Chunk>{{std::string("\xff\xff\x00" "7\r\n", 6)}};  // noise glued to a reply
            default: return std::vector<Chunk>{{"42\r\n"}};
        }
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64));
    // Noise that arrived before the request is stale and flushed.
    peer.port().write(as_bytes(noise));
    std::this_thread::sleep_for(50ms);
    EXPECT_THROW(link.transact("A"), ReplyTooLong);
    EXPECT_EQ(link.transact("B"), std::string("\xff\xff\x00" "7", 4));  // the link returns exact bytes
    EXPECT_EQ(link.transact("C"), "42");
    EXPECT_EQ(link.counters().stale_bytes, noise.size());
}

TEST(LineLink, A11_NulTerminatorOnly) {
    PtyPair pty;
    ScriptedPeer peer(pty, [&](const std::string&) {
        return std::vector<Chunk>{{std::string("12\r\n\0", 5)}};
    });
    LineLink link(pty.port(), opts({std::string("\0", 1)}));
    EXPECT_EQ(link.transact("@0PX"), "12\r\n");
}

TEST(LineLink, A11_CrLfIsNotEndedByCrAlone) {
    PtyPair pty;
    std::atomic<int> n{0};
    ScriptedPeer peer(pty, [&](const std::string&) {
        if (n++ == 0) return std::vector<Chunk>{{"5\r"}};  // CR alone: not our terminator
        return std::vector<Chunk>{{"6\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 40ms));
    EXPECT_THROW(link.transact("A"), TimeoutError);
    EXPECT_EQ(link.transact("B"), "6");
}

TEST(LineLink, AnyOfSeveralTerminators) {
    PtyPair pty;
    ScriptedPeer peer(pty, [&](const std::string& req) {
        if (req == "cr") return std::vector<Chunk>{{"a\r"}};
        if (req == "nul") return std::vector<Chunk>{{std::string("b\0", 2)}};
        return std::vector<Chunk>{{"c\r\n"}};
    });
    LineLink link(pty.port(), opts({"\r", "\r\n", std::string("\0", 1)}));
    EXPECT_EQ(link.transact("cr"), "a");
    EXPECT_EQ(link.transact("nul"), "b");
    EXPECT_EQ(link.transact("crlf"), "c");
    EXPECT_EQ(link.counters().stale_bytes, 0u);  // the LF of CR LF was not left behind
}

TEST(LineLink, EchoSuppressionSkipsOwnBytes) {
    PtyPair pty;
    ScriptedPeer peer(pty, [&](const std::string& req) { return std::vector<Chunk>{{req + "=9\r\n"}}; },
                      /*echo=*/true);
    auto o = opts();
    o.echo_suppression = true;
    o.turnaround = 1ms;
    LineLink link(pty.port(), o);
    EXPECT_EQ(link.transact("01READ"), "01READ=9");
    auto c = link.counters();
    EXPECT_EQ(c.echo_bytes, 7u);
    EXPECT_EQ(c.echo_mismatches, 0u);
}

TEST(LineLink, EchoSuppressionWithoutEchoKeepsReplyThatStartsLikeRequest) {
    PtyPair pty;
    // No echo, and the reply begins with the same bytes as the request.
    ScriptedPeer peer(pty, [&](const std::string&) { return std::vector<Chunk>{{"01"}, {"#VEL=5\r\n", 5ms}}; });
    auto o = opts();
    o.echo_suppression = true;
    LineLink link(pty.port(), o);
    EXPECT_EQ(link.transact("01READ #VEL"), "01#VEL=5");
    EXPECT_EQ(link.counters().echo_mismatches, 1u);
}

TEST(LineLink, NoFlushKeepsEarlyBytes) {
    PtyPair pty;
    auto peer = pty.open_slave();
    auto o = opts();
    o.flush_before_request = false;
    LineLink link(pty.port(), o);
    peer->write(as_bytes("early\r\n"));
    std::this_thread::sleep_for(50ms);
    EXPECT_EQ(link.transact("X"), "early");
}

TEST(LineLink, SendAndReadLineUnsolicited) {
    PtyPair pty;
    auto peer = pty.open_slave();
    LineLink link(pty.port(), opts({"\r\n"}));
    link.send("BROADCAST");
    std::uint8_t buf[32];
    std::string got;
    while (got.size() < 10) got.append(reinterpret_cast<char*>(buf), peer->read(buf, 1s));
    EXPECT_EQ(got, "BROADCAST\r");
    EXPECT_FALSE(link.read_line(10ms));
    peer->write(as_bytes("boot "));
    EXPECT_FALSE(link.read_line(10ms));  // partial stays buffered
    peer->write(as_bytes("v1.2\r\nnext\r\n"));
    EXPECT_EQ(link.read_line(1s), "boot v1.2");
    EXPECT_EQ(link.read_line(1s), "next");
}

TEST(LineLink, ConcurrentTransactionsAreSerialized) {
    PtyPair pty;
    ScriptedPeer peer(pty, [&](const std::string& req) {
        return std::vector<Chunk>{{"R:"}, {req + "\r\n", 1ms}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 2s));
    std::atomic<int> bad{0};
    std::vector<std::thread> ts;
    for (int t = 0; t < 4; ++t)
        ts.emplace_back([&, t] {
            for (int i = 0; i < 20; ++i) {
                std::string req = std::to_string(t * 1000 + i);
                std::string expected = "R:";
                expected += req;
                if (link.transact(req) != expected) ++bad;
            }
        });
    for (auto& t : ts) t.join();
    EXPECT_EQ(bad.load(), 0);
    EXPECT_EQ(link.counters().replies, 80u);
}

TEST(LineLink, AWaitingTransactionIsServedNextNotStarvedByALoop) {
    // A poller that reads a slow line back to back (always behind its deadlines)
    // must not keep another thread's command out: the command waits for the
    // transaction in progress, then goes.  Each reply takes 2 ms.
    PtyPair pty;
    std::atomic<int> served{0};
    ScriptedPeer peer(pty, [&](const std::string& req) {
        ++served;
        return std::vector<Chunk>{{req + "\r\n", 2ms}};
    });
    LineLink link(pty.port(), opts({"\r\n"}, 64, 2s));
    std::atomic<bool> stop{false};
    std::thread poller([&] {
        while (!stop) link.transact("poll");
    });
    while (served.load() < 5) std::this_thread::sleep_for(1ms);
    int worst = 0;
    for (int i = 0; i < 20; ++i) {
        const int before = served.load();
        EXPECT_EQ(link.transact("cmd" + std::to_string(i)), "cmd" + std::to_string(i));
        // Served between asking and the reply: the poll in progress (and one that
        // may have started just before the command took its turn), then the command.
        worst = std::max(worst, served.load() - before - 1);
        std::this_thread::sleep_for(1ms);
    }
    stop = true;
    poller.join();
    EXPECT_LE(worst, 2) << "polls served while a command waited for the line";
}

TEST(LineLink, LinkDownWhenPeerVanishes) {
    PtyPair pty;
    LineLink link(pty.port(), opts({"\r\n"}, 64, 1s));
    {
        auto peer = pty.open_slave();
        pty.release_slave();
    }
    EXPECT_THROW(link.transact("X"), LinkDown);
}

TEST(LineLink, RejectsBadOptions) {
    PtyPair pty;
    EXPECT_THROW(LineLink(pty.port(), opts({})), InvalidArgument);
    EXPECT_THROW(LineLink(nullptr, opts()), InvalidArgument);
    auto o = opts();
    o.max_line = 0;
    EXPECT_THROW(LineLink(pty.port(), o), InvalidArgument);
}
