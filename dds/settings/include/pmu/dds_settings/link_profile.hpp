#pragma once
// The link between a participant and its peers: `link:` in pmu-service's config
// ({profile: radio, round_trip: S}) and pmuctl's --link / $PMU_LINK (interface.md sections
// 4 and 7.3). A profile is a named bundle of settings for one kind of link; the finer keys
// (`round_trip`) override its values. No Fast DDS type here: dds_participant.hpp and
// DdsContext turn a LinkPlan into participant QoS and writer periods.
//
// Purpose: one definition of what "radio" sets, for the service and pmuctl alike, and one
// explanation of each value and where it came from (pmu-service --check-config).
//
// The radio profile (a narrow radio to the ground: 250 kbit/s, a round trip of 0.5..1 s):
//   round trip 0.7 s (the VM lab's fleet8: 300 ms each way with jitter): reliable writers
//     heartbeat at most every 1.5 round trips (config.hpp link round_trip says why);
//   participant announcements every 20 s with a lease of 60 s: each announcement crosses the
//     link to every peer, and a lease longer than a radio dropout of 30 s keeps the peers'
//     endpoints matched through it (deploy/README.md "Riding through a dropout");
//   one initial announcement instead of Fast DDS's five at 100 ms: a participant that starts
//     answers every other's announcement anyway, and eight aircraft starting together
//     otherwise send forty announcements into the link's queue at once;
//   discovery is not paced: in Fast DDS 2.9.1 the participant's throughput controller paces
//     only the announcement writer (the endpoint discovery writers are synchronous), and it
//     aborts when an announcement is queued again before the last one left
//     (FlowControllerImpl.hpp:1109, `!change->writer_info.is_linked`);
//   pmuctl watch reads the low-rate topics pmu/low_rate/* (pmuctl --link radio);
//   the service writes them every 2 s unless its config sets low_rate_period: each of the
//   five low-rate samples of a PMU crosses the link as a datagram of its own of about 200
//   bytes, 130 of them headers (IP, RTPS, the time stamp, Fast DDS's statistics submessage),
//   so a period of 1 s costs one aircraft's watcher about 1,000 B/s, 2 s about 500
//   (bench/results/2026-12-06-one-aircraft-low-rate.md);
//   pmuctl agent runs one worker (and its engine-stop lane) unless --workers says otherwise:
//     each worker is a participant of its own, which every aircraft sends all its endpoints to
//     and repairs that discovery for, pair by pair; with five ground participants and eight
//     aircraft the repairs of those forty pairs filled a 250 kbit/s link for good
//     (bench/fleet_link.sh). Through a Discovery Server that does not hold, and the agent
//     keeps its workers (resolve_network): eight calls at once, after a radio dropout, take
//     one round trip each rather than eight in a row.
//   Datagrams stay at most kUdpMaxMessageSize (1,400 B, one packet on a 1,500-byte MTU),
//   which every participant uses already (dds_participant.hpp).
// Without a profile and without round_trip nothing changes: Fast DDS's periods and qos.xml's.
//
// Error handling: parse_link_profile returns nullopt for a name it does not know; the config
// and pmuctl say where ("FILE:LINE: ...", "--link", "PMU_LINK").

#include <chrono>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pmu::dds {

enum class LinkProfile { None, Radio };

// "radio" -> Radio; "none" -> None (a LAN: an option that overrides an exported variable);
// anything else (also "") -> nullopt.
std::optional<LinkProfile> parse_link_profile(std::string_view text);
const char* to_string(LinkProfile profile) noexcept;
inline constexpr const char* kLinkProfileNames = "radio, none";

// What the config or pmuctl was given, with where each came from ("FILE:LINE", "--link",
// "PMU_LINK").
struct LinkSettings {
  LinkProfile profile = LinkProfile::None;
  std::string profile_where;
  std::optional<std::chrono::milliseconds> round_trip;
  std::string round_trip_where;
  // The service's config gives low_rate_period itself: the profile leaves it alone.
  bool low_rate_period_given = false;
};

// The radio profile's values (the header comment says why each).
inline constexpr std::chrono::milliseconds kRadioRoundTrip{700};
inline constexpr std::chrono::milliseconds kRadioAnnouncementPeriod{20000};
inline constexpr std::chrono::milliseconds kRadioLease{60000};
inline constexpr int kRadioInitialAnnouncements = 1;
inline constexpr int kRadioAgentWorkers = 1;
inline constexpr std::chrono::milliseconds kRadioLowRatePeriod{2000};

// One value a participant gets from the link settings, and where it came from.
struct LinkValue {
  std::chrono::milliseconds value{0};  // 0: not set (Fast DDS's or qos.xml's own)
  std::string from;                    // "profile radio (FILE:LINE)", "round_trip (FILE:LINE)"
  bool set() const noexcept { return value.count() > 0; }
};

struct LinkPlan {
  LinkProfile profile = LinkProfile::None;
  LinkValue round_trip;
  LinkValue heartbeat_floor;      // reliable writers heartbeat at most this often: 1.5 round trips
  LinkValue announcement_period;  // SPDP announcement period (multicast and unicast discovery)
  LinkValue lease;                // SPDP lease duration
  LinkValue low_rate_period;      // the service's low_rate_period when its config gives none
  int initial_announcements = 0;  // 0: Fast DDS's (5 at 100 ms)
  bool low_rate_watch = false;    // pmuctl watch reads pmu/low_rate/*
  int agent_workers = 0;          // pmuctl agent's workers when --workers is not given; 0: its default (4)
  // One line per value, for --check-config: "round trip 0.7 s (profile radio, s.yaml:3)".
  std::vector<std::string> explain() const;
};

LinkPlan link_plan(const LinkSettings& settings);

}  // namespace pmu::dds
