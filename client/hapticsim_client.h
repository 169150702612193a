#ifndef HAPTICSIM_CLIENT_H
#define HAPTICSIM_CLIENT_H

/*
 * hapticsim's shared-memory client as a C API: for a simulator or device driver written in C, or
 * in a language that calls C (Python's ctypes, C#'s P/Invoke, Unity, CHAI3D), to drive hapticsimd
 * on the same host without C++.
 *
 *   char why[256];
 *   hapticsim_client* c = hapticsim_connect(NULL, why, sizeof why);   // NULL: the default socket
 *   if (!c) { fprintf(stderr, "%s\n", why); return 1; }
 *   for (seq = 1; ...; ++seq) {                                         // every device period
 *     hapticsim_send_pose(c, seq, now_us, position_m);
 *     hapticsim_force f;
 *     if (hapticsim_read_force(c, &f) == 1 && hapticsim_is_live(c, now_ns)) render(f.force_n);
 *     else render_zero();
 *   }
 *   hapticsim_disconnect(c);
 *
 * hapticsim_send_pose, hapticsim_read_force, hapticsim_read_status, hapticsim_is_live and
 * hapticsim_read_deformation are wait-free (no locks, no allocation, no system calls): call them
 * from the device's real-time loop. hapticsim_connect, hapticsim_reconnect and
 * hapticsim_disconnect are not. A client is used by one real-time thread (one writer of poses),
 * any threads that only read (a render thread reading the deformed surface) and, for
 * hapticsim_reconnect, one other thread.
 *
 * Units: metres, newtons, microseconds (utime) and nanoseconds (CLOCK_MONOTONIC), as on LCM.
 * Link: -lhapticsim_client (pkg-config hapticsim-client; CMake: hapticsim::client).
 */

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(__GNUC__)
#define HAPTICSIM_API __attribute__((visibility("default")))
#else
#define HAPTICSIM_API
#endif

/** The daemon's default service socket (its shm.socket). */
#define HAPTICSIM_DEFAULT_SOCKET "/run/hapticsim/hapticsimd.sock"

/* The bits of hapticsim_force.flags: the same as force_feedback_t's FLAG_* on LCM. */
#define HAPTICSIM_FLAG_IN_CONTACT 1 /* the contact is engaged: the force is the tissue's */
#define HAPTICSIM_FLAG_ERROR_TARGET_EXCEEDED 2 /* no stable configuration meets the target */
#define HAPTICSIM_FLAG_LOOKUP_CLAMPED 4        /* the scene is outside the map: edge value used */
#define HAPTICSIM_FLAG_INPUT_STALE 8           /* no valid input for longer than stale_after */
#define HAPTICSIM_FLAG_RECONFIGURING 16        /* the regions are being changed */
#define HAPTICSIM_FLAG_NO_ERROR_MAP 32         /* no map loaded: error_percent is -1 */
#define HAPTICSIM_FLAG_INPUT_REJECTED 64       /* the newest pose was rejected (see the log) */
#define HAPTICSIM_FLAG_BOUNDARY_STALE 128      /* a secondary region has not run for over 0.1 s */
#define HAPTICSIM_FLAG_FORCE_LIMITED 256       /* the port guard changed the force sent */
#define HAPTICSIM_FLAG_PORT_DISSIPATING 512    /* the passivity controller took energy out */
#define HAPTICSIM_FLAG_FAULT_LATCHED 1024      /* a latched fault holds the force at zero */

/** One session with hapticsimd. Opaque. */
typedef struct hapticsim_client hapticsim_client;

/** The daemon's answer for one of its primary periods. */
typedef struct hapticsim_force {
  int64_t period;       /* the daemon's primary period, counting every one from 0 */
  int64_t seq;          /* the newest pose it answers (-1: none yet) */
  int64_t first_seq;    /* the oldest it answers: every pose from first_seq to seq was used */
  int64_t utime_us;     /* when it was computed, daemon's CLOCK_MONOTONIC, µs */
  double force_n[3];    /* force on the user, N, object frame (pressing in pushes back: -z) */
  double error_percent; /* looked-up force error, % of the reference peak (-1: no map) */
  int32_t flags;        /* HAPTICSIM_FLAG_* bits */
} hapticsim_force;

/** What the session knows about the daemon. */
typedef struct hapticsim_status {
  int64_t daemon_pid;     /* the daemon's process id; 0 once it stopped cleanly (a killed daemon
                             leaves it: hapticsim_is_live is what says a force is computed) */
  int32_t daemon_running; /* daemon_pid != 0: not stopped cleanly (see daemon_pid) */
  int64_t heartbeat_ns;   /* CLOCK_MONOTONIC of its newest answer (0: none yet) */
  int64_t newest_period;  /* the newest period answered (-1: none yet) */
  int64_t poses_sent;     /* hapticsim_send_pose calls in this session */
} hapticsim_status;

/** One frame of the deformed surface (hapticsim_read_deformation). */
typedef struct hapticsim_deformation {
  int64_t frame;            /* frames the daemon made since it started ([deformation] rate_hz) */
  int64_t utime_us;         /* when it was made, daemon's CLOCK_MONOTONIC, µs */
  int64_t configuration_id; /* changes whenever the regions are replaced (ids may then differ) */
  int32_t in_contact;       /* 1: the tool engaged within the last 5 primary periods */
  int32_t complete;         /* 1: every region published its part after being asked */
  int32_t nodes_per_axis;   /* n: node id = (ix * n + iy) * n + iz (the largest node count of
                               the object's lattice, nodes 0 … its largest index; its faces:
                               ObjectSurfaceQuads in core/scene/object_surface.hpp) */
  int32_t contact_node[3];  /* lattice indices the regions are centred on */
  double spacing_m;         /* lattice spacing, m: a node rests at (ix, iy, iz) * spacing_m */
  int32_t num_nodes;        /* surface nodes written into the caller's arrays */
} hapticsim_deformation;

/**
 * Connects to hapticsimd's service socket (NULL: HAPTICSIM_DEFAULT_SOCKET) and maps the shared
 * memory it hands over; waits up to 2 s to connect and 2 s for the daemon's answer. Returns NULL
 * when it cannot, with the reason in `error` (what to fix: no daemon there, not in its group,
 * another driver holds the session, a socket another user could have put there), truncated to
 * `error_size` bytes.
 */
HAPTICSIM_API hapticsim_client* hapticsim_connect(const char* socket_path, char* error,
                                                  size_t error_size);

/** Ends the session and frees `client` (NULL: nothing). The daemon goes on serving. */
HAPTICSIM_API void hapticsim_disconnect(hapticsim_client* client);

/**
 * The tool tip's position (object frame, m), once per device period: `seq` increases by one per
 * call (the daemon answers it in hapticsim_force.seq), `utime_us` is the caller's clock.
 * Returns 0, or -1 when an argument is NULL. Wait-free.
 */
HAPTICSIM_API int hapticsim_send_pose(hapticsim_client* client, int64_t seq, int64_t utime_us,
                                      const double position_m[3]);

/**
 * The newest force into `out`. Returns 1 when there is one, 0 when the daemon has not answered
 * yet (or is being written this instant: call again next period), -1 when an argument is NULL.
 * A dead daemon leaves its last answer readable: check hapticsim_is_live before rendering it.
 * Wait-free.
 */
HAPTICSIM_API int hapticsim_read_force(const hapticsim_client* client, hapticsim_force* out);

/**
 * 1 while the daemon runs and its newest answer is at most 10 ms old at `now_ns`
 * (CLOCK_MONOTONIC); else 0: nobody computes the force read, render zero (and call
 * hapticsim_reconnect now and then from another thread). Wait-free.
 */
HAPTICSIM_API int hapticsim_is_live(const hapticsim_client* client, int64_t now_ns);

/** The session's status into `out`. Returns 0, or -1 when an argument is NULL. Wait-free. */
HAPTICSIM_API int hapticsim_read_status(const hapticsim_client* client, hapticsim_status* out);

/** Surface nodes in each frame of the deformed surface: the arrays' size, in nodes, that
 *  hapticsim_read_deformation needs. 0 for NULL. */
HAPTICSIM_API int32_t hapticsim_deformation_nodes(const hapticsim_client* client);

/**
 * The newest frame of the deformed surface (docs/simulator.md, "The deformed shape"): its facts
 * into `out`, the surface node ids into `node_ids` and their displacements into `displacement_m`
 * (x, y, z per node, m, object frame), each with room for `capacity_nodes` nodes
 * (hapticsim_deformation_nodes); either array may be NULL. Returns 1 when there is a frame
 * (out->num_nodes filled), 0 when the daemon has written none yet ([deformation] rate_hz = 0, or
 * just started) or its writes raced every try (the arrays may then hold parts of several frames),
 * -1, nothing written, when `client` or `out` is NULL or the surface has more nodes than
 * `capacity_nodes` (after hapticsim_reconnect to a daemon of another object: ask
 * hapticsim_deformation_nodes again). Wait-free: it may be called from another thread of the
 * driver's process, a render thread, while the device thread sends poses.
 */
HAPTICSIM_API int hapticsim_read_deformation(const hapticsim_client* client,
                                             hapticsim_deformation* out, int32_t* node_ids,
                                             double* displacement_m, int32_t capacity_nodes);

/**
 * After a daemon restart: a new session at the same socket. Returns 1 when it connected, 0 when
 * not (the old session stays). Not wait-free (up to 400 ms): call it off the real-time thread
 * while hapticsim_is_live says 0; the real-time thread may go on meanwhile.
 */
HAPTICSIM_API int hapticsim_reconnect(hapticsim_client* client);

/** The library's version, "MAJOR.MINOR.PATCH". */
HAPTICSIM_API const char* hapticsim_client_version(void);

#ifdef __cplusplus
}
#endif

#endif /* HAPTICSIM_CLIENT_H */
