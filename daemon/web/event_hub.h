// The web server's live feed (GET /api/events): each published message goes to every open
// event stream, each stream with a queue of its own, so a slow browser only ever delays
// itself. A stream whose queue overflows is ended (the browser's EventSource reconnects and
// the page fetches what it missed); publish() never blocks on a stream.
//
// Threading: publish() and close() from any thread (the daemon's job listener, the device
// poller); each Subscriber is read by the one server thread that serves its stream.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

namespace atelier::web {

class EventHub;

class Subscriber {
 public:
  // The next message, waiting up to `timeout`; nullopt on timeout or once ended().
  std::optional<std::string> next(std::chrono::milliseconds timeout);
  // True once the hub closed or this stream fell too far behind; then next() returns nullopt.
  bool ended();

 private:
  friend class EventHub;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::string> queue_;
  bool ended_ = false;
};

class EventHub {
 public:
  // At most `max_streams` open streams; each holds at most `max_queued` unread messages.
  EventHub(size_t max_streams, size_t max_queued);
  ~EventHub();

  // A new stream, or nullptr when `max_streams` are open (the caller answers 503). The stream
  // is dropped from the hub when the last shared_ptr to it goes.
  std::shared_ptr<Subscriber> subscribe();
  // Sends `message` (a whole server-sent event, "event: ...\ndata: ...\n\n") to every stream.
  void publish(const std::string& message);
  // Ends every stream and refuses new ones (the server is stopping).
  void close();
  size_t streams();

 private:
  size_t max_streams_, max_queued_;
  std::mutex mu_;
  std::list<std::weak_ptr<Subscriber>> subscribers_;
  bool closed_ = false;
};

// A server-sent event: "event: NAME\ndata: DATA\n\n" (DATA must be one line, as JSON dumps are).
std::string sse_message(const std::string& name, const std::string& data);

}  // namespace atelier::web
