// cyclone_ros2_reader: what rmw_cyclonedds does for a ROS 2 subscriber, on Eclipse Cyclone
// DDS's C API: the DDS topic "rt" + the ROS 2 name, the type name
// <pkg>::msg::dds_::<Name>_, ROS 2's default reader QoS (RELIABLE, VOLATILE, KEEP_LAST 10), no
// partition. It reads a PMU's battery A, a BMS's battery and /diagnostics from pmu-service
// (ros2: enabled) and prints, for each, one line of the values it decoded:
//   battery_a voltage=24.6 current=2 temperature=25 present=1 status=1 health=1 location=battery_a serial=pmu 4321
// Exit status: 0 each arrived (/diagnostics: an OK status) within 30 s, 1 one did not, 2 bad usage or no DDS.
//   cyclone_ros2_reader DOMAIN DEVICE_PREFIX   (e.g. 7 /test/uav1/sim)
#include <dds/dds.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "diagnostic_msgs/msg/DiagnosticArray.h"
#include "sensor_msgs/msg/BatteryState.h"

namespace {

dds_qos_t* ros2_default_qos() {
  dds_qos_t* q = dds_create_qos();
  dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
  dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
  dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 10);
  // Fast DDS 2.9 writes XCDR1 only (tests/cyclone/cyclone_client.cpp says why this is pinned).
  const dds_data_representation_id_t r[] = {DDS_DATA_REPRESENTATION_XCDR1};
  dds_qset_data_representation(q, 1, r);
  return q;
}

dds_entity_t reader(dds_entity_t pp, const dds_topic_descriptor_t* type, const std::string& topic) {
  const dds_entity_t t = dds_create_topic(pp, type, topic.c_str(), nullptr, nullptr);
  if (t < 0) return t;
  dds_qos_t* q = ros2_default_qos();
  const dds_entity_t r = dds_create_reader(pp, t, q, nullptr);
  dds_delete_qos(q);
  return r;
}

// Takes samples of `r` until `done` accepts one, for up to 30 s.
template <class T, class Done>
bool wait_for(dds_entity_t r, Done done) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    void* samples[1] = {nullptr};
    dds_sample_info_t info[1];
    while (dds_take(r, samples, info, 1, 1) > 0) {
      const bool ok = info[0].valid_data && done(*static_cast<const T*>(samples[0]));
      dds_return_loan(r, samples, 1);
      if (ok) return true;
      samples[0] = nullptr;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

void print_battery(const char* what, const sensor_msgs_msg_dds__BatteryState_& m) {
  std::printf(
      "%s voltage=%g current=%g temperature=%g percentage=%g charge=%g design_capacity=%g cells=%u "
      "present=%d status=%u health=%u location=%s serial=%s frame_id=%s\n",
      what, static_cast<double>(m.voltage), static_cast<double>(m.current), static_cast<double>(m.temperature),
      static_cast<double>(m.percentage), static_cast<double>(m.charge), static_cast<double>(m.design_capacity),
      m.cell_voltage._length, m.present ? 1 : 0, m.power_supply_status, m.power_supply_health, m.location,
      m.serial_number, m.header.frame_id);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: cyclone_ros2_reader DOMAIN DEVICE_PREFIX\n");
    return 2;
  }
  const auto domain = static_cast<dds_domainid_t>(std::strtoul(argv[1], nullptr, 10));
  const std::string prefix = argv[2];
  const dds_entity_t pp = dds_create_participant(domain, nullptr, nullptr);
  if (pp < 0) {
    std::fprintf(stderr, "cyclone_ros2_reader: no participant: %s\n", dds_strretcode(pp));
    return 2;
  }
  const dds_entity_t pmu_a = reader(pp, &sensor_msgs_msg_dds__BatteryState__desc, "rt" + prefix + "/pmu_1/battery_a");
  const dds_entity_t bms = reader(pp, &sensor_msgs_msg_dds__BatteryState__desc, "rt" + prefix + "/bms_2/battery");
  const dds_entity_t diag = reader(pp, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics");
  if (pmu_a < 0 || bms < 0 || diag < 0) {
    std::fprintf(stderr, "cyclone_ros2_reader: cannot create the readers\n");
    dds_delete(pp);
    return 2;
  }
  int missed = 0;
  using Battery = sensor_msgs_msg_dds__BatteryState_;
  if (!wait_for<Battery>(pmu_a, [](const Battery& m) {
        if (std::isnan(m.current) || std::isnan(m.temperature) || m.serial_number[0] == '\0') return false;
        print_battery("battery_a", m);
        return true;
      })) {
    std::printf("MISS battery_a\n");
    ++missed;
  }
  if (!wait_for<Battery>(bms, [](const Battery& m) {
        if (m.cell_voltage._length != 12 || std::isnan(m.percentage)) return false;
        for (uint32_t i = 0; i < m.cell_voltage._length; ++i)
          if (std::isnan(m.cell_voltage._buffer[i])) return false;
        print_battery("bms", m);
        return true;
      })) {
    std::printf("MISS bms\n");
    ++missed;
  }
  using Array = diagnostic_msgs_msg_dds__DiagnosticArray_;
  // Each array holds every device's newest status (interface.md 11.3). A device's first status
  // may be STALE "no frame yet", published before its first frame: every status is printed,
  // and the wait ends at the first array whose statuses are all OK.
  if (!wait_for<Array>(diag, [](const Array& a) {
        if (a.status._length == 0) return false;
        bool all_ok = true;
        for (uint32_t i = 0; i < a.status._length; ++i) {
          const auto& s = a.status._buffer[i];
          std::printf("diagnostics name=%s level=%u message=%s hardware_id=%s values=%u\n", s.name,
                      static_cast<unsigned>(s.level), s.message, s.hardware_id, s.values._length);
          all_ok = all_ok && s.level == 0;
        }
        return all_ok;
      })) {
    std::printf("MISS diagnostics\n");
    ++missed;
  }
  dds_delete(pp);
  return missed == 0 ? 0 : 1;
}
