/* qemu_multicast_if.c: preloaded into the arm64 pmu-service that arm64_e2e.sh runs under
 * qemu-user. Debian bookworm's qemu-user (7.2) does not translate setsockopt(IPPROTO_IP,
 * IP_MULTICAST_IF) and answers ENOPROTOOPT; Fast DDS 2.9 sets that option on every UDP
 * output socket and, when it fails, opens no output channel at all, so the participant
 * could never send. This accepts that one option without passing it on (multicast then
 * leaves by the routing table's interface, which on one host reaches every local
 * participant); every other call goes to the kernel unchanged. Real arm64 hardware needs
 * none of this: the kernel supports the option on every architecture.
 */
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/syscall.h>
#include <unistd.h>

int setsockopt(int fd, int level, int name, const void* value, socklen_t length) {
  if (level == IPPROTO_IP && name == IP_MULTICAST_IF) return 0;
  return (int)syscall(SYS_setsockopt, fd, level, name, value, length);
}
