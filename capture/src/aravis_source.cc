#include "core/clock.h"
#include "capture/aravis_source.h"
#include "capture/camera_time.h"

#include <arv.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <deque>
#include <mutex>
#include <thread>
#include <utility>

namespace studio::capture {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;


// Takes ownership of a GError: its message, and clears it.
std::string take_error(GError*& error) {
  std::string message = error ? error->message : "unknown error";
  g_clear_error(&error);
  for (char& c : message) {
    if (c == '\n') c = ' ';
  }
  return message;
}

// The GenICam names the Aravis pixel format codes stand for (for buffers).
Expected<CameraPixelFormat> from_arv(ArvPixelFormat format) {
  switch (format) {
    case ARV_PIXEL_FORMAT_MONO_8:
      return CameraPixelFormat::mono8;
    case ARV_PIXEL_FORMAT_RGB_8_PACKED:
      return CameraPixelFormat::rgb8;
    case ARV_PIXEL_FORMAT_BAYER_RG_8:
      return CameraPixelFormat::bayer_rg8;
    case ARV_PIXEL_FORMAT_BAYER_GR_8:
      return CameraPixelFormat::bayer_gr8;
    case ARV_PIXEL_FORMAT_BAYER_GB_8:
      return CameraPixelFormat::bayer_gb8;
    case ARV_PIXEL_FORMAT_BAYER_BG_8:
      return CameraPixelFormat::bayer_bg8;
    default:
      break;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%08X", unsigned(format));
  return fail(std::string("unsupported pixel format ") + hex +
              " (supported: Mono8, RGB8, BayerRG8/GR8/GB8/BG8)");
}

void select_interfaces(const std::vector<std::string>& interfaces) {
  if (interfaces.empty()) return;
  for (unsigned i = 0; i < arv_get_n_interfaces(); ++i) {
    const std::string id = arv_get_interface_id(i);
    if (std::find(interfaces.begin(), interfaces.end(), id) != interfaces.end()) {
      arv_enable_interface(id.c_str());
    } else {
      arv_disable_interface(id.c_str());
    }
  }
}

const char* const kExtraFeatures[] = {"BlackLevel", "Gamma", "Focus", "Zoom", "Iris"};

// White balance: SFNC's BalanceRatio of the channel BalanceRatioSelector names, published as one
// flat feature per channel (our features are name -> value); green is the reference.
struct BalanceChannel {
  const char* feature;
  const char* selector;
};
constexpr BalanceChannel kBalanceChannels[] = {{"BalanceRatioRed", "Red"},
                                               {"BalanceRatioBlue", "Blue"}};

// The camera has a selectable BalanceRatio (the caller holds the device mutex).
bool has_balance_ratio(ArvCamera* camera) {
  return arv_camera_is_feature_available(camera, "BalanceRatioSelector", nullptr) &&
         arv_camera_is_feature_available(camera, "BalanceRatio", nullptr);
}

}  // namespace

Expected<void> AravisOptions::validate() const {
  const std::string who = "aravis camera '" + device_id + "'";
  if (width < 0 || height < 0) return fail(who + ": width/height must not be negative");
  if ((width == 0) != (height == 0)) return fail(who + ": give both width and height, or neither");
  if (!(frame_rate >= 0 && frame_rate <= 10000)) return fail(who + ": frame_rate out of range");
  if (buffers < 2 || buffers > 256) return fail(who + ": buffers must be in 2..256");
  if (trigger == TriggerMode::line && trigger_line.empty()) {
    return fail(who + ": trigger_line is empty");
  }
  if (!clock.valid()) return fail(who + ": clock period must be positive");
  if (retry_initial.count() <= 0 || retry_max < retry_initial) {
    return fail(who + ": need 0 < retry_initial <= retry_max");
  }
  if (lost_after.count() <= 0) return fail(who + ": lost_after must be positive");
  for (const std::string& i : interfaces) {
    if (i != "Fake" && i != "GigEVision" && i != "USB3Vision" && i != "GenTL") {
      return fail(who + ": unknown Aravis interface '" + i + "'");
    }
  }
  return {};
}

std::vector<std::string> list_aravis_devices(const std::vector<std::string>& interfaces) {
  select_interfaces(interfaces);
  arv_update_device_list();
  std::vector<std::string> ids;
  for (unsigned i = 0; i < arv_get_n_devices(); ++i) ids.push_back(arv_get_device_id(i));
  return ids;
}

struct AravisSource::Impl {
  AravisOptions options;
  std::string id;

  // Owned by next()'s thread; guarded by device_mutex for the other threads' feature access.
  mutable std::mutex device_mutex;
  ArvCamera* camera = nullptr;
  ArvStream* stream = nullptr;
  gulong lost_handler = 0;
  std::atomic<bool> control_lost{false};
  bool acquiring = false;

  // Reconnection state (next()'s thread).
  bool want_acquisition = false;
  Clock::time_point next_retry{};
  milliseconds backoff{};
  Clock::time_point last_activity{};

  std::atomic<bool> stopping{false};
  mutable std::mutex stats_mutex;
  SourceStats stats;
  uint64_t own_drops = 0;       // error-status buffers and conversion failures
  uint64_t past_underruns = 0;  // from streams of earlier connections
  Config config;

  std::vector<std::thread> reapers;  // finalising lost devices

  // Camera time (next()'s thread) and the clock trigger thread.
  CameraTimeLatch latch;
  std::atomic<TimeSource> time_source{TimeSource::host_arrival};
  std::thread trigger_thread;
  std::atomic<bool> trigger_run{false};
  std::atomic<uint64_t> triggers{0};
  std::mutex trigger_mutex;
  std::deque<uint64_t> triggered;  // studio frames triggered, not yet delivered

  ~Impl() {
    stop_trigger();
    disconnect(/*device_alive=*/!control_lost);
    for (std::thread& t : reapers) t.join();
  }

  static void on_control_lost(ArvDevice*, gpointer self) {
    static_cast<Impl*>(self)->control_lost = true;
  }

  uint64_t stream_underruns() const {
    if (!stream) return 0;
    guint64 completed = 0, failures = 0, underruns = 0;
    arv_stream_get_statistics(stream, &completed, &failures, &underruns);
    return underruns;
  }

  void update_drops() {
    const uint64_t underruns = stream_underruns();
    std::lock_guard lock(stats_mutex);
    stats.drops = own_drops + past_underruns + underruns;
  }

  void set_connected(bool connected) {
    SourceStats copy;
    {
      std::lock_guard lock(stats_mutex);
      if (stats.connected == connected) return;
      stats.connected = connected;
      if (connected) ++stats.reconnects;
      copy = stats;
    }
    if (options.on_state) options.on_state(copy);
  }

  // Opens the device and applies the configuration; on failure leaves nothing open.
  Expected<void> connect() {
    std::lock_guard lock(device_mutex);
    GError* error = nullptr;
    const char* name = options.device_id.empty() ? nullptr : options.device_id.c_str();
    ArvCamera* cam = arv_camera_new(name, &error);
    if (!cam)
      return fail("aravis: cannot open camera '" + options.device_id + "': " + take_error(error));
    camera = cam;
    if (auto ok = configure(); !ok) {
      disconnect_locked(true);
      return ok;
    }
    return {};
  }

  Expected<void> configure() {
    GError* error = nullptr;
    const std::string who = "aravis camera '" + id + "'";
    auto check = [&](const char* what) -> Expected<void> {
      if (!error) return {};
      return fail(who + ": " + what + ": " + take_error(error));
    };
    arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, &error);
    if (auto ok = check("AcquisitionMode"); !ok) return ok;
    if (options.pixel_format != CameraPixelFormat::keep) {
      const char* want = genicam_name(options.pixel_format);
      arv_camera_set_pixel_format_from_string(camera, want, &error);
      if (auto ok = check("CameraPixelFormat"); !ok) return ok;
      const char* got = arv_camera_get_pixel_format_as_string(camera, &error);
      if (auto ok = check("CameraPixelFormat"); !ok) return ok;
      if (!got || std::string(got) != want) {
        return fail(who + ": CameraPixelFormat " + want + " not accepted (reads back " +
                    (got ? got : "nothing") + ")");
      }
    }
    if (options.width > 0) {
      // Aravis does not range-check by default: check the bounds and increments first.
      gint wmin = 0, wmax = 0, hmin = 0, hmax = 0;
      arv_camera_get_width_bounds(camera, &wmin, &wmax, &error);
      if (!error) arv_camera_get_height_bounds(camera, &hmin, &hmax, &error);
      if (auto ok = check("size bounds"); !ok) return ok;
      const gint winc = std::max(1, arv_camera_get_width_increment(camera, nullptr));
      const gint hinc = std::max(1, arv_camera_get_height_increment(camera, nullptr));
      if (options.width < wmin || options.width > wmax || options.height < hmin ||
          options.height > hmax || (options.width - wmin) % winc ||
          (options.height - hmin) % hinc) {
        return fail(who + ": size " + std::to_string(options.width) + "x" +
                    std::to_string(options.height) + " not supported (width " +
                    std::to_string(wmin) + ".." + std::to_string(wmax) + " step " +
                    std::to_string(winc) + ", height " + std::to_string(hmin) + ".." +
                    std::to_string(hmax) + " step " + std::to_string(hinc) + ")");
      }
      arv_camera_set_region(camera, 0, 0, options.width, options.height, &error);
      if (auto ok = check("region"); !ok) return ok;
      gint x = 0, y = 0, w = 0, h = 0;
      arv_camera_get_region(camera, &x, &y, &w, &h, &error);
      if (auto ok = check("region"); !ok) return ok;
      if (w != options.width || h != options.height) {
        return fail(who + ": size " + std::to_string(options.width) + "x" +
                    std::to_string(options.height) + " not accepted (reads back " +
                    std::to_string(w) + "x" + std::to_string(h) + ")");
      }
    }
    switch (options.trigger) {
      case TriggerMode::free_run:
        arv_camera_clear_triggers(camera, &error);
        if (auto ok = check("TriggerMode Off"); !ok) return ok;
        if (options.frame_rate > 0) {
          arv_camera_set_frame_rate(camera, options.frame_rate, &error);
          if (auto ok = check("AcquisitionFrameRate"); !ok) return ok;
          const double got = arv_camera_get_frame_rate(camera, &error);
          if (auto ok = check("AcquisitionFrameRate"); !ok) return ok;
          if (std::abs(got - options.frame_rate) > 1e-3 * options.frame_rate) {
            return fail(who + ": frame rate " + std::to_string(options.frame_rate) +
                        " not accepted (reads back " + std::to_string(got) + ")");
          }
        }
        break;
      case TriggerMode::software:
        arv_camera_set_trigger(camera, "Software", &error);
        if (auto ok = check("software trigger"); !ok) return ok;
        break;
      case TriggerMode::line:
        arv_camera_set_trigger(camera, options.trigger_line.c_str(), &error);
        if (auto ok = check(("trigger on " + options.trigger_line).c_str()); !ok) return ok;
        break;
    }

    Config c;
    const char* pf = arv_camera_get_pixel_format_as_string(camera, &error);
    c.pixel_format = pf ? pf : "";
    gint x = 0, y = 0;
    arv_camera_get_region(camera, &x, &y, &c.width, &c.height, &error);
    if (arv_camera_is_frame_rate_available(camera, nullptr)) {
      c.frame_rate = arv_camera_get_frame_rate(camera, &error);
    }
    if (auto ok = check("reading the configuration back"); !ok) return ok;
    auto str = [](const char* s) { return std::string(s ? s : ""); };
    c.vendor = str(arv_camera_get_vendor_name(camera, nullptr));
    c.model = str(arv_camera_get_model_name(camera, nullptr));
    c.serial = str(arv_camera_get_device_serial_number(camera, nullptr));
    c.payload_bytes = arv_camera_get_payload(camera, &error);
    if (auto ok = check("payload size"); !ok) return ok;
    if (auto fmt = parse_pixel_format(c.pixel_format); !fmt || *fmt == CameraPixelFormat::keep) {
      return fail(who + ": the camera's pixel format " + c.pixel_format +
                  " is not supported (set pixel_format to Mono8, RGB8 or a Bayer 8 format)");
    }

    stream = arv_camera_create_stream(camera, nullptr, nullptr, &error);
    if (!stream) return fail(who + ": cannot create stream: " + take_error(error));
    for (int i = 0; i < options.buffers; ++i) {
      arv_stream_push_buffer(stream, arv_buffer_new_allocate(c.payload_bytes));
    }
    control_lost = false;
    if (arv_camera_is_gv_device(camera)) {
      lost_handler = g_signal_connect(arv_camera_get_device(camera), "control-lost",
                                      G_CALLBACK(&Impl::on_control_lost), this);
    }
    {
      std::lock_guard lock(stats_mutex);
      config = c;
    }
    return {};
  }

  Expected<void> start_acquisition() {
    std::lock_guard lock(device_mutex);
    latch_camera_time();  // (re)connected: the camera's clock may have restarted
    GError* error = nullptr;
    arv_camera_start_acquisition(camera, &error);
    if (error) return fail("aravis camera '" + id + "': AcquisitionStart: " + take_error(error));
    acquiring = true;
    last_activity = Clock::now();
    return {};
  }

  void stop_acquisition() {
    std::lock_guard lock(device_mutex);
    GError* error = nullptr;
    if (camera && acquiring) arv_camera_stop_acquisition(camera, &error);
    g_clear_error(&error);
    acquiring = false;
  }

  void disconnect(bool device_alive) {
    std::lock_guard lock(device_mutex);
    disconnect_locked(device_alive);
  }

  // A lost device is not sent AcquisitionStop (every register access would time out).
  void disconnect_locked(bool device_alive) {
    if (camera && acquiring && device_alive) {
      GError* error = nullptr;
      arv_camera_stop_acquisition(camera, &error);
      g_clear_error(&error);
    }
    acquiring = false;
    if (lost_handler && camera) {
      g_signal_handler_disconnect(arv_camera_get_device(camera), lost_handler);
    }
    lost_handler = 0;
    if (stream) {
      past_underruns += stream_underruns();
      g_object_unref(stream);
      stream = nullptr;
    }
    if (camera) {
      g_object_unref(camera);
      camera = nullptr;
    }
  }

  // The device is gone: publish the state at once, then release the Aravis objects on a reaper
  // thread (finalising a GigE device whose camera vanished blocks for seconds on its farewell
  // register writes).
  void lose() {
    ArvStream* old_stream = nullptr;
    ArvCamera* old_camera = nullptr;
    {
      std::lock_guard lock(device_mutex);
      if (lost_handler && camera) {
        g_signal_handler_disconnect(arv_camera_get_device(camera), lost_handler);
      }
      lost_handler = 0;
      past_underruns += stream_underruns();
      old_stream = std::exchange(stream, nullptr);
      old_camera = std::exchange(camera, nullptr);
      acquiring = false;
    }
    backoff = options.retry_initial;
    next_retry = Clock::now() + backoff;
    update_drops();
    set_connected(false);
    reapers.emplace_back([old_stream, old_camera] {
      if (old_stream) g_object_unref(old_stream);
      if (old_camera) g_object_unref(old_camera);
    });
  }

  // True when the device answers a register read.
  bool probe() {
    std::lock_guard lock(device_mutex);
    // One bootstrap register (address 0: GigE Vision "Version", USB3 Vision ABRM "GenCP
    // version"): a single transaction, so a dead device costs one GVCP timeout, not one per
    // feature node.
    GError* error = nullptr;
    guint32 value = 0;
    arv_device_read_register(arv_camera_get_device(camera), 0, &value, &error);
    if (!error) return true;
    g_clear_error(&error);
    return false;
  }

  Expected<void> trigger_locked() {
    if (!camera) return fail("camera " + id + ": software trigger: camera is disconnected");
    GError* error = nullptr;
    arv_camera_software_trigger(camera, &error);
    if (error) return fail("camera " + id + ": software trigger: " + take_error(error));
    ++triggers;
    return {};
  }

  // Fires the software trigger at every studio frame, half a period in (genlock instant).
  void start_trigger() {
    if (options.trigger != TriggerMode::software || !options.clock_trigger || trigger_run) return;
    if (trigger_thread.joinable()) trigger_thread.join();  // ended by stop()
    trigger_run = true;
    trigger_thread = std::thread([this] {
      const FrameClock& clock = options.clock;
      uint64_t f = clock.frame_at(realtime_ns()) + 1;
      while (trigger_run) {
        const int64_t due = clock.time_of(f) + clock.period_ns / 2;
        // Absolute sleeps on CLOCK_REALTIME in slices of at most 50 ms (stop stays prompt).
        for (int64_t now = realtime_ns(); trigger_run && now < due; now = realtime_ns()) {
          const int64_t until = std::min(due, now + 50'000'000);
          timespec ts{time_t(until / 1'000'000'000), long(until % 1'000'000'000)};
          clock_nanosleep(CLOCK_REALTIME, TIMER_ABSTIME, &ts, nullptr);
        }
        if (!trigger_run) break;
        {
          std::lock_guard lock(device_mutex);
          if (camera && acquiring && trigger_locked()) {
            std::lock_guard t(trigger_mutex);
            triggered.push_back(f);
            while (triggered.size() > 64) triggered.pop_front();
          }
        }
        // A late wake-up (a loaded host) skips to the next frame not yet due: one trigger per
        // frame, never a burst.
        f = std::max(f + 1, clock.frame_at(realtime_ns() - clock.period_ns / 2) + 1);
      }
    });
  }

  // Clock-triggered frames carry the number of the studio frame whose trigger made them (the
  // oldest trigger not yet answered; triggers whose answer never came, passed by a frame taken
  // after the next trigger, count as drops). A frame nobody triggered is not delivered.
  bool frame_of_trigger(Frame& frame) {
    if (options.trigger != TriggerMode::software || !options.clock_trigger) return true;
    std::lock_guard lock(trigger_mutex);
    const FrameClock& c = options.clock;
    while (triggered.size() > 1 &&
           c.time_of(triggered[1]) + c.period_ns / 2 <= frame.capture_ns) {
      triggered.pop_front();
      ++own_drops;
    }
    if (triggered.empty() || c.time_of(triggered.front()) + c.period_ns / 2 > frame.capture_ns)
      return false;
    frame.frame = triggered.front();
    triggered.pop_front();
    return true;
  }

  void stop_trigger() {
    trigger_run = false;
    if (trigger_thread.joinable()) trigger_thread.join();
  }

  // Seeds the camera-time latch from a GenICam timestamp latch, when the camera has one.
  void latch_camera_time() {
    latch.reset();
    if (!options.camera_time || !camera) return;
    ArvDevice* device = arv_camera_get_device(camera);
    struct Names {
      const char *latch, *value;
      bool ticks;
    };
    for (const Names n : {Names{"TimestampLatch", "TimestampLatchValue", false},
                          Names{"GevTimestampControlLatch", "GevTimestampValue", true}}) {
      if (!arv_device_is_feature_available(device, n.latch, nullptr) ||
          !arv_device_is_feature_available(device, n.value, nullptr))
        continue;
      GError* error = nullptr;
      const int64_t before = realtime_ns();
      arv_device_execute_command(device, n.latch, &error);
      const gint64 value = error ? 0 : arv_device_get_integer_feature_value(device, n.value, &error);
      const int64_t after = realtime_ns();
      double ns_per_tick = 1;
      if (!error && n.ticks) {
        const gint64 hz =
            arv_device_get_integer_feature_value(device, "GevTimestampTickFrequency", &error);
        if (!error && hz > 0) ns_per_tick = 1e9 / double(hz);
      }
      if (error) {
        g_clear_error(&error);
        continue;
      }
      latch.latch(int64_t(double(value) * ns_per_tick), before, after);
      return;
    }
  }

  // Sleeps until `until` in short slices, returning early on stop().
  void nap(Clock::time_point until) {
    while (!stopping && Clock::now() < until) {
      std::this_thread::sleep_for(
          std::min<Clock::duration>(until - Clock::now(), milliseconds(20)));
    }
  }
};

AravisSource::AravisSource(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AravisSource::~AravisSource() = default;

Expected<std::unique_ptr<AravisSource>> AravisSource::open(const AravisOptions& options) {
  if (auto ok = options.validate(); !ok) return std::unexpected(ok.error());
  select_interfaces(options.interfaces);
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->id = !options.camera_id.empty() ? options.camera_id : options.device_id;
  if (auto ok = impl->connect(); !ok) return std::unexpected(ok.error());
  if (impl->id.empty()) impl->id = impl->config.vendor + "-" + impl->config.serial;
  return std::unique_ptr<AravisSource>(new AravisSource(std::move(impl)));
}

const std::string& AravisSource::id() const { return impl_->id; }

Expected<void> AravisSource::start() {
  Impl& d = *impl_;
  d.stopping = false;
  d.want_acquisition = true;
  d.start_trigger();
  if (!d.camera) return {};  // lost: next() reconnects and starts
  if (d.acquiring) return {};
  return d.start_acquisition();
}

void AravisSource::stop() {
  impl_->stopping = true;
  impl_->trigger_run = false;  // the thread ends within 50 ms; joined by the next start/destructor
}

TimeSource AravisSource::time_source() const { return impl_->time_source; }
uint64_t AravisSource::triggers() const { return impl_->triggers; }

Expected<std::optional<Frame>> AravisSource::next(std::chrono::milliseconds timeout) {
  Impl& d = *impl_;
  const auto deadline = Clock::now() + timeout;
  if (!d.want_acquisition) return fail("aravis camera '" + d.id + "': next() before start()");
  for (;;) {
    if (d.stopping) {
      if (d.acquiring) d.stop_acquisition();
      return std::optional<Frame>();
    }
    if (!d.camera) {  // lost: retry with back-off
      if (Clock::now() >= d.next_retry) {
        if (d.connect() && d.start_acquisition()) {
          d.update_drops();
          d.set_connected(true);
          continue;
        }
        d.disconnect(false);
        d.backoff = std::min(d.backoff * 2, d.options.retry_max);
        d.next_retry = Clock::now() + d.backoff;
      }
      if (Clock::now() >= deadline) return std::optional<Frame>();
      d.nap(std::min(deadline, d.next_retry));
      continue;
    }
    if (d.control_lost) {
      d.lose();
      continue;
    }
    const auto now = Clock::now();
    if (now >= deadline) {
      d.update_drops();
      return std::optional<Frame>();
    }
    const auto slice = std::min<Clock::duration>(deadline - now, milliseconds(100));
    const guint64 slice_us = guint64(
        std::max<int64_t>(1, std::chrono::duration_cast<std::chrono::microseconds>(slice).count()));
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(d.stream, slice_us);
    if (!buffer) {
      if (Clock::now() - d.last_activity > d.options.lost_after) {
        if (!d.probe()) {
          d.lose();
          continue;
        }
        d.last_activity = Clock::now();
      }
      continue;
    }
    d.last_activity = Clock::now();
    std::optional<Frame> frame;
    bool unsolicited = false;  // a frame no clock trigger asked for: ignored, not a drop
    if (arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS) {
      size_t size = 0;
      const void* data = arv_buffer_get_image_data(buffer, &size);
      auto format = from_arv(arv_buffer_get_image_pixel_format(buffer));
      Expected<Image<Rgb8>> image =
          format ? convert_to_rgb(
                       *format, std::span<const uint8_t>(static_cast<const uint8_t*>(data), size),
                       arv_buffer_get_image_width(buffer), arv_buffer_get_image_height(buffer))
                 : std::unexpected(format.error());
      if (image) {
        frame.emplace();
        const guint64 system_ns = arv_buffer_get_system_timestamp(buffer);
        const int64_t arrival = system_ns ? int64_t(system_ns) : realtime_ns();
        std::optional<int64_t> camera_ns;
        if (d.options.camera_time)
          camera_ns = d.latch.frame(int64_t(arv_buffer_get_timestamp(buffer)), arrival);
        frame->capture_ns = camera_ns ? *camera_ns : arrival;
        d.time_source = camera_ns ? TimeSource::camera : TimeSource::host_arrival;
        frame->frame = d.options.clock.frame_at(frame->capture_ns);
        frame->image = std::move(*image);
        if (!d.frame_of_trigger(*frame)) {
          frame.reset();
          unsolicited = true;
        }
      }
    }
    arv_stream_push_buffer(d.stream, buffer);
    {
      std::lock_guard lock(d.stats_mutex);
      if (frame) {
        ++d.stats.frames;
      } else if (!unsolicited) {
        ++d.own_drops;
      }
    }
    d.update_drops();
    if (frame) return frame;
  }
}

std::vector<Feature> AravisSource::features() const {
  Impl& d = *impl_;
  std::lock_guard lock(d.device_mutex);
  std::vector<Feature> out;
  if (!d.camera) return out;
  GError* error = nullptr;
  auto add = [&](const char* name, double value, double min, double max) {
    if (error) {
      g_clear_error(&error);
      return;
    }
    out.push_back(Feature{name, value, min, max, true});
  };
  double min = 0, max = 0;
  if (arv_camera_is_gain_available(d.camera, nullptr)) {
    arv_camera_get_gain_bounds(d.camera, &min, &max, &error);
    add("Gain", error ? 0 : arv_camera_get_gain(d.camera, &error), min, max);
  }
  if (arv_camera_is_exposure_time_available(d.camera, nullptr)) {
    arv_camera_get_exposure_time_bounds(d.camera, &min, &max, &error);
    add("ExposureTime", error ? 0 : arv_camera_get_exposure_time(d.camera, &error), min, max);
  }
  if (arv_camera_is_frame_rate_available(d.camera, nullptr)) {
    arv_camera_get_frame_rate_bounds(d.camera, &min, &max, &error);
    add("AcquisitionFrameRate", error ? 0 : arv_camera_get_frame_rate(d.camera, &error), min, max);
  }
  if (has_balance_ratio(d.camera))
    for (const BalanceChannel& b : kBalanceChannels) {
      arv_camera_set_string(d.camera, "BalanceRatioSelector", b.selector, &error);
      if (!error) arv_camera_get_float_bounds(d.camera, "BalanceRatio", &min, &max, &error);
      add(b.feature, error ? 0 : arv_camera_get_float(d.camera, "BalanceRatio", &error), min, max);
    }
  ArvGc* genicam = arv_device_get_genicam(arv_camera_get_device(d.camera));
  for (const char* name : kExtraFeatures) {
    ArvGcNode* node = arv_gc_get_node(genicam, name);
    if (!node || !arv_camera_is_feature_available(d.camera, name, nullptr)) continue;
    if (ARV_IS_GC_FLOAT(node)) {
      arv_camera_get_float_bounds(d.camera, name, &min, &max, &error);
      add(name, error ? 0 : arv_camera_get_float(d.camera, name, &error), min, max);
    } else if (ARV_IS_GC_INTEGER(node)) {
      gint64 imin = 0, imax = 0;
      arv_camera_get_integer_bounds(d.camera, name, &imin, &imax, &error);
      add(name, error ? 0 : double(arv_camera_get_integer(d.camera, name, &error)), double(imin),
          double(imax));
    }
  }
  return out;
}

Expected<double> AravisSource::set_feature(std::string_view name_view, double value) {
  Impl& d = *impl_;
  const std::string name(name_view);
  const std::string who = "camera " + d.id + ": " + name;
  if (!std::isfinite(value)) return fail(who + ": value is not finite");
  std::lock_guard lock(d.device_mutex);
  if (!d.camera) return fail(who + ": camera is disconnected");
  GError* error = nullptr;
  double min = 0, max = 0, got = 0;
  auto done = [&](const char* what) -> Expected<double> {
    if (error) return fail(who + ": " + what + ": " + take_error(error));
    return got;
  };
  if (name == "Gain") {
    arv_camera_get_gain_bounds(d.camera, &min, &max, &error);
    if (!error) arv_camera_set_gain(d.camera, std::clamp(value, min, max), &error);
    if (!error) got = arv_camera_get_gain(d.camera, &error);
    return done("set");
  }
  if (name == "ExposureTime") {
    arv_camera_get_exposure_time_bounds(d.camera, &min, &max, &error);
    if (!error) arv_camera_set_exposure_time(d.camera, std::clamp(value, min, max), &error);
    if (!error) got = arv_camera_get_exposure_time(d.camera, &error);
    return done("set");
  }
  if (name == "AcquisitionFrameRate") {
    arv_camera_get_frame_rate_bounds(d.camera, &min, &max, &error);
    if (!error) arv_camera_set_frame_rate(d.camera, std::clamp(value, min, max), &error);
    if (!error) got = arv_camera_get_frame_rate(d.camera, &error);
    return done("set");
  }
  for (const BalanceChannel& b : kBalanceChannels) {
    if (name != b.feature) continue;
    if (!has_balance_ratio(d.camera)) return fail(who + ": not available on this camera");
    arv_camera_set_string(d.camera, "BalanceRatioSelector", b.selector, &error);
    if (!error) arv_camera_get_float_bounds(d.camera, "BalanceRatio", &min, &max, &error);
    if (!error) arv_camera_set_float(d.camera, "BalanceRatio", std::clamp(value, min, max), &error);
    if (!error) got = arv_camera_get_float(d.camera, "BalanceRatio", &error);
    return done("set");
  }
  if (std::find(std::begin(kExtraFeatures), std::end(kExtraFeatures), name) ==
      std::end(kExtraFeatures)) {
    return fail(who +
                ": not a remotely controllable feature (Gain, ExposureTime, "
                "AcquisitionFrameRate, BalanceRatioRed, BalanceRatioBlue, BlackLevel, Gamma, "
                "Focus, Zoom, Iris)");
  }
  ArvGcNode* node =
      arv_gc_get_node(arv_device_get_genicam(arv_camera_get_device(d.camera)), name.c_str());
  if (!node || !arv_camera_is_feature_available(d.camera, name.c_str(), nullptr)) {
    return fail(who + ": not available on this camera");
  }
  if (ARV_IS_GC_FLOAT(node)) {
    arv_camera_get_float_bounds(d.camera, name.c_str(), &min, &max, &error);
    if (!error) arv_camera_set_float(d.camera, name.c_str(), std::clamp(value, min, max), &error);
    if (!error) got = arv_camera_get_float(d.camera, name.c_str(), &error);
    return done("set");
  }
  if (ARV_IS_GC_INTEGER(node)) {
    gint64 imin = 0, imax = 0;
    arv_camera_get_integer_bounds(d.camera, name.c_str(), &imin, &imax, &error);
    const double clamped = std::clamp(std::round(value), double(imin), double(imax));
    if (!error) arv_camera_set_integer(d.camera, name.c_str(), gint64(clamped), &error);
    if (!error) got = double(arv_camera_get_integer(d.camera, name.c_str(), &error));
    return done("set");
  }
  return fail(who + ": not a numeric feature");
}

SourceStats AravisSource::stats() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->stats;
}

Expected<void> AravisSource::software_trigger() {
  Impl& d = *impl_;
  std::lock_guard lock(d.device_mutex);
  if (!d.camera) return fail("camera " + d.id + ": software trigger: camera is disconnected");
  if (d.options.trigger != TriggerMode::software) {
    return fail("camera " + d.id +
                ": software trigger: the camera is not in software trigger mode");
  }
  return d.trigger_locked();
}

AravisSource::Config AravisSource::config() const {
  std::lock_guard lock(impl_->stats_mutex);
  return impl_->config;
}

}  // namespace studio::capture
