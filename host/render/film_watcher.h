// Something that shows the film while it fills (display/live_view.h, the tev viewer). The
// pool's merger asks it between passes, so a watcher costs the devices nothing: only the
// merger's time, and only when the watcher wants a frame.
#pragma once

namespace fh {

struct Film;

class FilmWatcher {
 public:
  virtual ~FilmWatcher() = default;
  // Whether a frame is due now (cheap: asked after every merged pass).
  virtual bool wantsFrame() = 0;
  // The film as merged so far; called on the merger's thread, which owns the film meanwhile.
  virtual void show(const Film& film) = 0;
};

}  // namespace fh
