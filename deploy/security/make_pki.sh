#!/usr/bin/env bash
# make_pki.sh: creates a complete DDS-Security PKI for pmu-dds with openssl.
#
#   deploy/security/make_pki.sh OUTDIR [--days N] [--ca-days N] [--domain N|MIN-MAX]
#                               [--vehicles LIST] [--ground-station NAME=LIST]... [--force]
#
#   OUTDIR          where everything goes (created; refused if it already holds a PKI,
#                   unless --force)
#   --days N        validity of the identity certificates and of the permission grants,
#                   in days (default 365)
#   --ca-days N     validity of the two CA certificates, in days (default 3650)
#   --domain D      the DDS domain id (N) or range (MIN-MAX) that governance and
#                   permissions cover (default 0)
#   --vehicles LIST
#                   confine pmu-service, ground-station and mission-computer to these
#                   vehicles: LIST is comma separated vehicle names (config `vehicle`,
#                   docs/interface.md 7.1: 0..15 letters, digits, '_', '-', '.'); an empty
#                   name (--vehicles '', --vehicles ,uav1) is the unnamed vehicle, i.e. the
#                   default partition. Default: every vehicle (partition pattern "*")
#   --ground-station NAME=LIST
#                   one more identity NAME (certificate, key, permissions) with the rights
#                   of ground-station, confined to the vehicles of LIST (as for --vehicles).
#                   Repeatable. pmuctl with such an identity must name --vehicle
#   --force         replace an existing PKI in OUTDIR (every key and certificate is new)

# What it makes (deploy/security/README.md explains each file and where it goes):
#   OUTDIR/identity_ca.pem          Identity CA certificate (issues the identities)
#   OUTDIR/permissions_ca.pem       Permissions CA certificate (signs governance and
#                                   permissions only: it issues no certificate at all)
#   OUTDIR/governance.xml, .p7s     domain rules; .p7s is what DDS reads (S/MIME, signed
#                                   by the Permissions CA)
#   OUTDIR/NAME/cert.pem, key.pem   identity of NAME (pmu-service, ground-station,
#                                   mission-computer and each --ground-station NAME),
#                                   signed by the Identity CA
#   OUTDIR/NAME/permissions.xml, .p7s   what NAME may publish and subscribe, and in which
#                                   DDS partitions (= vehicles)
#   OUTDIR/ca/                      the two CA private keys and the openssl CA database.
#                                   Keep it offline; never install or commit it.
#
# Keys are ECDSA P-256 and every signature is ecdsa-with-SHA256 (what Fast DDS 2.9's
# builtin PKI-DH and Access-Permissions plugins accept). The two CAs are separate on
# purpose: Fast DDS 2.9.1 lacks the fix for CVE-2023-24010, so with one CA for identities
# and permissions any participant could sign its own permissions.
#
# Vehicles: each pmu-service sits in the DDS partition named after its vehicle (the unnamed
# vehicle: the default partition), and Fast DDS 2.9 creates a writer or reader only in
# partitions that the identity's allow rule grants: each partition the endpoint asks for is
# matched (fnmatch) against the granted patterns, and a rule without <partitions> grants the
# default partition alone. So every rule here names its partitions: "*" (which matches every
# name and the default partition too) unless --vehicles or --ground-station confine it.
#
# Exit status: 0 on success, 1 on an error, 2 on bad usage.

set -euo pipefail
export LC_ALL=C  # [A-Za-z] means ASCII letters and ${#v} counts bytes, as in vehicle.cpp

usage() { sed -n '2,/^$/p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
die() { echo "make_pki.sh: $*" >&2; exit 1; }

out=""
days=365
ca_days=3650
domain="0"
force=0
vehicles="*"        # the standard identities' partitions, comma separated ("*": every vehicle)
extra=()            # --ground-station identities: NAME
declare -A extra_vehicles=()  # NAME -> its comma separated vehicles

# Why NAME cannot be a vehicle name, or nothing: dds/settings/src/vehicle.cpp
# vehicle_name_problem, word for word. ('*', '?', '[' would be patterns in a partition.)
vehicle_problem() {
  local v=$1
  if [ ${#v} -gt 15 ]; then
    echo "is ${#v} characters; a vehicle name has at most 15 (it is a DDS key)"
  elif [[ "$v" =~ [^A-Za-z0-9_.-] ]]; then
    local bad=${v//[A-Za-z0-9_.-]/}
    echo "contains '${bad:0:1}'; a vehicle name is letters, digits, '_', '-' and '.' (it is also a DDS partition name, where other characters are patterns)"
  fi
}
# split_list LIST: one line per comma separated item; empty items stay (the unnamed vehicle).
split_list() {
  local s=$1
  while :; do
    printf '%s\n' "${s%%,*}"
    [[ "$s" == *,* ]] || break
    s=${s#*,}
  done
}
# check_vehicles OPTION LIST: exit 2 with the reason when an item is not a vehicle name.
check_vehicles() {
  local v why
  while IFS= read -r v; do
    why=$(vehicle_problem "$v")
    [ -z "$why" ] || { echo "make_pki.sh: $1: vehicle '$v' $why" >&2; exit 2; }
  done < <(split_list "$2")
}

while [ $# -gt 0 ]; do
  case "$1" in
    --days) [ $# -ge 2 ] || { usage >&2; exit 2; }; days=$2; shift 2 ;;
    --ca-days) [ $# -ge 2 ] || { usage >&2; exit 2; }; ca_days=$2; shift 2 ;;
    --domain) [ $# -ge 2 ] || { usage >&2; exit 2; }; domain=$2; shift 2 ;;
    --vehicles)
      [ $# -ge 2 ] || { usage >&2; exit 2; }
      check_vehicles --vehicles "$2"; vehicles=$2; shift 2 ;;
    --ground-station)
      [ $# -ge 2 ] || { usage >&2; exit 2; }
      [[ "$2" == *=* ]] || { echo "make_pki.sh: --ground-station '$2': expected NAME=VEHICLE[,VEHICLE...]" >&2; exit 2; }
      name=${2%%=*}
      [[ "$name" =~ ^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$ ]] ||
        { echo "make_pki.sh: --ground-station: identity name '$name' must be 1..64 letters, digits, '_', '-', '.' (not starting with '-' or '.'): it is a folder and a certificate's CN" >&2; exit 2; }
      case "$name" in
        pmu-service|ground-station|mission-computer|ca)
          echo "make_pki.sh: --ground-station: '$name' is taken (pmu-service, ground-station, mission-computer and ca are make_pki.sh's own)" >&2; exit 2 ;;
      esac
      [ -z "${extra_vehicles[$name]+x}" ] || { echo "make_pki.sh: --ground-station $name given twice" >&2; exit 2; }
      check_vehicles "--ground-station $name" "${2#*=}"
      extra+=("$name"); extra_vehicles[$name]=${2#*=}; shift 2 ;;
    --force) force=1; shift ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "make_pki.sh: unknown option '$1'" >&2; usage >&2; exit 2 ;;
    *) [ -z "$out" ] || { echo "make_pki.sh: more than one OUTDIR" >&2; exit 2; }; out=$1; shift ;;
  esac
done
[ -n "$out" ] || { usage >&2; exit 2; }
[[ "$days" =~ ^[1-9][0-9]*$ ]] || { echo "make_pki.sh: --days must be a positive integer, not '$days'" >&2; exit 2; }
[[ "$ca_days" =~ ^[1-9][0-9]*$ ]] || { echo "make_pki.sh: --ca-days must be a positive integer, not '$ca_days'" >&2; exit 2; }
if [[ "$domain" =~ ^([0-9]+)-([0-9]+)$ ]]; then
  dmin=${BASH_REMATCH[1]}; dmax=${BASH_REMATCH[2]}
elif [[ "$domain" =~ ^[0-9]+$ ]]; then
  dmin=$domain; dmax=$domain
else
  echo "make_pki.sh: --domain must be N or MIN-MAX, not '$domain'" >&2; exit 2
fi
{ [ "$dmin" -le "$dmax" ] && [ "$dmax" -le 232 ]; } || { echo "make_pki.sh: --domain $domain is not within 0..232" >&2; exit 2; }
[ "$ca_days" -ge "$days" ] || { echo "make_pki.sh: --ca-days ($ca_days) must be at least --days ($days)" >&2; exit 2; }
command -v openssl >/dev/null || die "openssl is not installed (apt-get install openssl)"

standard=(pmu-service ground-station mission-computer)
identities=("${standard[@]}" "${extra[@]}")
org="pmu-dds"

if [ -e "$out/identity_ca.pem" ] || [ -e "$out/ca" ]; then
  [ "$force" -eq 1 ] || die "$out already holds a PKI; use --force to replace it (every key is made anew)"
  # The old PKI's --ground-station identities too (ca/identities lists them): their
  # certificates would not verify against the new Identity CA.
  old=()
  if [ -f "$out/ca/identities" ]; then
    while IFS= read -r n; do
      [[ "$n" =~ ^[A-Za-z0-9][A-Za-z0-9_.-]{0,63}$ ]] && [ "$n" != ca ] && old+=("$n")
    done < "$out/ca/identities"
  fi
  rm -rf "${out:?}/ca" "$out/identity_ca.pem" "$out/permissions_ca.pem" "$out/governance.xml" "$out/governance.p7s"
  for n in "${identities[@]}" "${old[@]}"; do rm -rf "${out:?}/$n"; done
fi
mkdir -p "$out"
out=$(cd "$out" && pwd)
umask 077
mkdir -p "$out/ca/issued"
: > "$out/ca/index.txt"
echo 1000 > "$out/ca/serial"
printf '%s\n' "${identities[@]}" > "$out/ca/identities"

# openssl configuration: the Identity CA database (`openssl ca -name identity_ca`) and the
# extensions of each kind of certificate. Tests reuse it to issue odd certificates
# (expired ones) from the same Identity CA.
cat > "$out/ca/openssl.cnf" <<CNF
# pmu-dds test/site PKI (made by deploy/security/make_pki.sh)
dir = $out/ca

[ req ]
distinguished_name = req_dn
prompt = no
[ req_dn ]
O = $org

[ identity_ca ]
database = \$dir/index.txt
serial = \$dir/serial
new_certs_dir = \$dir/issued
certificate = $out/identity_ca.pem
private_key = \$dir/identity_ca.key
default_md = sha256
default_days = $days
policy = identity_policy
unique_subject = no
copy_extensions = none
email_in_dn = no
x509_extensions = identity_cert

[ identity_policy ]
organizationName = supplied
commonName = supplied

# The Identity CA: issues participant certificates, nothing else below it.
[ identity_ca_cert ]
basicConstraints = critical, CA:TRUE, pathlen:0
keyUsage = critical, keyCertSign, cRLSign
subjectKeyIdentifier = hash

# The Permissions CA: signs the governance and permissions documents (S/MIME), nothing
# else. Without keyCertSign a certificate it signed would not verify, so no identity can
# ever chain to it (and sign documents in its name).
[ permissions_ca_cert ]
basicConstraints = critical, CA:TRUE, pathlen:0
keyUsage = critical, digitalSignature
subjectKeyIdentifier = hash

# A participant identity (PKI-DH signs its handshake with this key).
[ identity_cert ]
basicConstraints = critical, CA:FALSE
keyUsage = critical, digitalSignature, keyAgreement
subjectKeyIdentifier = hash
authorityKeyIdentifier = keyid
CNF
cnf="$out/ca/openssl.cnf"

newkey() { openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$1" 2>/dev/null; }

# ---- the two CAs -------------------------------------------------------------------------
newkey "$out/ca/identity_ca.key"
openssl req -config "$cnf" -new -x509 -sha256 -days "$ca_days" -key "$out/ca/identity_ca.key" \
  -subj "/O=$org/CN=$org Identity CA" -extensions identity_ca_cert -out "$out/identity_ca.pem"
newkey "$out/ca/permissions_ca.key"
openssl req -config "$cnf" -new -x509 -sha256 -days "$ca_days" -key "$out/ca/permissions_ca.key" \
  -subj "/O=$org/CN=$org Permissions CA" -extensions permissions_ca_cert -out "$out/permissions_ca.pem"

# ---- identities --------------------------------------------------------------------------
for n in "${identities[@]}"; do
  mkdir -p "$out/$n"
  newkey "$out/$n/key.pem"
  openssl req -config "$cnf" -new -sha256 -key "$out/$n/key.pem" -subj "/O=$org/CN=$n" -out "$out/ca/$n.csr"
  openssl ca -config "$cnf" -name identity_ca -batch -notext -days "$days" \
    -in "$out/ca/$n.csr" -out "$out/$n/cert.pem" 2>/dev/null ||
    die "openssl ca could not issue the certificate of $n"
  rm -f "$out/ca/$n.csr"
done

# ---- governance ----------------------------------------------------------------------------
# Element order is the OMG XSD's; Fast DDS 2.9's parser insists on it.
topic_rule() {  # topic_rule EXPRESSION METADATA_PROTECTION DATA_PROTECTION
  cat <<XML
        <topic_rule>
          <topic_expression>$1</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>$2</metadata_protection_kind>
          <data_protection_kind>$3</data_protection_kind>
        </topic_rule>
XML
}
if [ "$dmin" -eq "$dmax" ]; then
  domains_xml="<id>$dmin</id>"
else
  domains_xml="<id_range><min>$dmin</min><max>$dmax</max></id_range>"
fi
{
  cat <<XML
<?xml version="1.0" encoding="UTF-8"?>
<!-- pmu-dds governance (made by deploy/security/make_pki.sh). Signed by the Permissions CA
     into governance.p7s, which is the file DDS reads.
     No unauthenticated participant; join access control on; discovery, liveliness and
     every RTPS message encrypted; every pmu topic read- and write-access-controlled (what
     each identity may do is in its permissions) with its data encrypted; the command
     topics' metadata encrypted as well. Any other topic: access controlled too, so the
     permissions' default DENY refuses it. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains>$domains_xml</domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
XML
  topic_rule "pmu/command" ENCRYPT ENCRYPT
  topic_rule "pmu/command_reply" ENCRYPT ENCRYPT
  topic_rule "pmu/alarm_ack" ENCRYPT ENCRYPT
  topic_rule "pmu/alarm_ack_reply" ENCRYPT ENCRYPT
  topic_rule "pmu/*" ENCRYPT ENCRYPT
  topic_rule "*" ENCRYPT ENCRYPT
  cat <<XML
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML
} > "$out/governance.xml"

sign() {  # sign IN OUT: S/MIME, signed by the Permissions CA, content inside
  openssl smime -sign -text -nodetach -in "$1" -out "$2" \
    -signer "$out/permissions_ca.pem" -inkey "$out/ca/permissions_ca.key" ||
    die "openssl smime could not sign $1"
}
sign "$out/governance.xml" "$out/governance.p7s"

# ---- permissions ---------------------------------------------------------------------------
telemetry=(pmu/voltages pmu/currents pmu/battery_energy pmu/temperatures pmu/status
           pmu/low_rate/voltages pmu/low_rate/currents pmu/low_rate/battery_energy pmu/low_rate/temperatures
           pmu/low_rate/status pmu/battery pmu/battery_cells pmu/mppt)
state=(pmu/config pmu/info pmu/health pmu/low_rate/health pmu/alarms pmu/readiness pmu/energy pmu/baseline pmu/bms_energy)

topics_xml() { for t in "$@"; do printf '            <topic>%s</topic>\n' "$t"; done; }
# partitions_xml LIST: one <partition> per vehicle of LIST; the unnamed vehicle ("") is an
# empty <partition></partition>, which Fast DDS 2.9 reads as the default partition.
partitions_xml() {
  local v
  while IFS= read -r v; do printf '            <partition>%s</partition>\n' "$v"; done < <(split_list "$1")
}
rule_xml() {  # rule_xml publish|subscribe PARTITIONS TOPIC...: PARTITIONS as for partitions_xml
  local kind=$1 parts=$2; shift 2
  printf '        <%s>\n          <topics>\n' "$kind"
  topics_xml "$@"
  printf '          </topics>\n          <partitions>\n'
  partitions_xml "$parts"
  printf '          </partitions>\n        </%s>\n' "$kind"
}
not_before=$(date -u +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "+$days days" +%Y-%m-%dT%H:%M:%S)

permissions() {  # permissions NAME ROLE VEHICLES -> the permissions XML of NAME on stdout
  local n=$1 role=$2 parts=$3
  cat <<XML
<?xml version="1.0" encoding="UTF-8"?>
<!-- pmu-dds permissions of $n (made by deploy/security/make_pki.sh). Signed by the
     Permissions CA into permissions.p7s. Anything not allowed here is denied. Partitions
     are vehicles: "*" is every vehicle, an empty one the unnamed vehicle. -->
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170801/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="$n">
      <subject_name>CN=$n,O=$org</subject_name>
      <validity>
        <not_before>$not_before</not_before>
        <not_after>$not_after</not_after>
      </validity>
      <allow_rule>
        <domains>$domains_xml</domains>
XML
  case "$role" in
    pmu-service)  # publishes telemetry, state and replies; reads commands and acknowledgements;
                  # as one of a hot-standby pair, writes and reads pmu/role and answers moves
      rule_xml publish "$parts" "${telemetry[@]}" "${state[@]}" pmu/command_reply pmu/alarm_ack_reply \
        pmu/role pmu/role_move_reply
      rule_xml subscribe "$parts" pmu/command pmu/alarm_ack pmu/role pmu/role_move
      ;;
    ground-station)  # the only one that may command, acknowledge or move a role; reads everything the service publishes
      rule_xml publish "$parts" pmu/command pmu/alarm_ack pmu/role_move
      rule_xml subscribe "$parts" "${telemetry[@]}" "${state[@]}" pmu/command_reply pmu/alarm_ack_reply \
        pmu/role pmu/role_move_reply
      ;;
    mission-computer)  # listens to telemetry, state and the pair's roles, nothing else: an alarm is the operator's to acknowledge
      rule_xml subscribe "$parts" "${telemetry[@]}" "${state[@]}" pmu/role
      ;;
  esac
  cat <<XML
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
XML
}
for n in "${standard[@]}"; do
  permissions "$n" "$n" "$vehicles" > "$out/$n/permissions.xml"
done
for n in "${extra[@]}"; do
  permissions "$n" ground-station "${extra_vehicles[$n]}" > "$out/$n/permissions.xml"
done
for n in "${identities[@]}"; do
  sign "$out/$n/permissions.xml" "$out/$n/permissions.p7s"
done

chmod 755 "$out" "${identities[@]/#/$out/}"
chmod 644 "$out"/*.pem "$out"/governance.* "$out"/*/cert.pem "$out"/*/permissions.*
chmod 600 "$out"/*/key.pem
chmod 700 "$out/ca"

echo "make_pki.sh: PKI in $out (domain $domain; identities valid $days days, CAs $ca_days days)"
echo "  identities: ${identities[*]}"
vehicles_text() {  # vehicles_text LIST: "every vehicle (*)" or "(unnamed), uav1"
  if [ "$1" = "*" ]; then echo "every vehicle (*)"; return; fi
  split_list "$1" | sed 's/^$/(unnamed)/' | paste -sd, - | sed 's/,/, /g'
}
echo "  vehicles of ${standard[*]}: $(vehicles_text "$vehicles")"
for n in "${extra[@]}"; do echo "  vehicles of $n: $(vehicles_text "${extra_vehicles[$n]}")"; done
echo "  keep $out/ca offline: it holds the CA keys"
