#!/usr/bin/env bash
# make_variants.sh: the bad identities the security tests throw at pmu-service, made from
# a PKI that deploy/security/make_pki.sh created (it needs that PKI's CA keys).
#
#   make_variants.sh foreign    PKI OUT              a complete PKI of its own (own Identity
#                                                    and Permissions CA, same identity names)
#   make_variants.sh selfsigned PKI OUT              mission-computer with permissions it
#                                                    signed itself (publish pmu/command),
#                                                    the CVE-2023-24010 shape; its own
#                                                    permissions_ca.pem holds the real
#                                                    Permissions CA and the Identity CA
#   make_variants.sh lax        PKI OUT              mission-computer with its real identity
#                                                    and permissions, but a governance (signed
#                                                    by the real Permissions CA) that leaves
#                                                    pmu/command without write access
#                                                    control: its own participant then lets
#                                                    it write commands, as a tampered
#                                                    library would; only the service's check
#                                                    of its permissions can stop it
#   make_variants.sh single-ca  PKI OUT              OUT/world: pmu-service and ground-station
#                                                    in a PKI with ONE CA that issues the
#                                                    identities and signs the documents
#                                                    (what make_pki.sh avoids); OUT/intruder:
#                                                    its mission-computer with permissions it
#                                                    signed itself (CVE-2023-24010 control)
#   make_variants.sh window     PKI OUT START END    ground-station (same subject, new key)
#                                                    with a certificate from the real
#                                                    Identity CA valid START..END
#                                                    (openssl dates, YYYYMMDDHHMMSSZ)
#
# Every variant is laid out like make_pki.sh's output (OUT/identity_ca.pem, OUT/NAME/...),
# so pmu::dds::security_files_in(OUT, NAME) names its six files.

set -euo pipefail
die() { echo "make_variants.sh: $*" >&2; exit 1; }
[ $# -ge 3 ] || die "usage: make_variants.sh foreign|selfsigned|window PKI OUT [START END]"
kind=$1 pki=$(cd "$2" && pwd) out=$3
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
make_pki="$here/../../deploy/security/make_pki.sh"
mkdir -p "$out"
out=$(cd "$out" && pwd)
umask 077

case "$kind" in
  foreign)
    domain=$(sed -n 's:.*<domains>\(.*\)</domains>.*:\1:p' "$pki/governance.xml" | head -1)
    if [[ "$domain" =~ \<min\>([0-9]+)\</min\>\<max\>([0-9]+)\</max\> ]]; then
      d="${BASH_REMATCH[1]}-${BASH_REMATCH[2]}"
    else
      d=$(sed 's:<id>\([0-9]*\)</id>:\1:' <<<"$domain")
    fi
    "$make_pki" "$out" --force --domain "$d" >/dev/null
    ;;
  selfsigned)
    n=mission-computer
    mkdir -p "$out/$n"
    cp "$pki/identity_ca.pem" "$out/identity_ca.pem"
    # Its own trust anchors for documents: the real Permissions CA first (Fast DDS announces
    # the first certificate's subject as its permissions CA, so the service sees the name
    # it expects), then the Identity CA, which issued its certificate and so lets its own
    # participant accept documents it signed itself. Only the signature can give it away.
    cat "$pki/permissions_ca.pem" "$pki/identity_ca.pem" > "$out/permissions_ca.pem"
    cp "$pki/$n/cert.pem" "$pki/$n/key.pem" "$out/$n/"
    # The ground station's rights under the mission computer's name.
    sed -e "s:CN=ground-station,O=pmu-dds:CN=$n,O=pmu-dds:" -e "s:grant name=\"ground-station\":grant name=\"$n\":" \
      "$pki/ground-station/permissions.xml" > "$out/$n/permissions.xml"
    grep -q "CN=$n,O=pmu-dds" "$out/$n/permissions.xml" || die "could not rewrite the permissions"
    for doc in "$out/$n/permissions" "$out/governance"; do
      src="$doc.xml"
      [ -f "$src" ] || cp "$pki/governance.xml" "$src"
      openssl smime -sign -text -nodetach -in "$src" -out "$doc.p7s" \
        -signer "$out/$n/cert.pem" -inkey "$out/$n/key.pem"
    done
    ;;
  lax)
    n=mission-computer
    mkdir -p "$out/$n"
    cp "$pki/identity_ca.pem" "$pki/permissions_ca.pem" "$out/"
    cp "$pki/$n/cert.pem" "$pki/$n/key.pem" "$pki/$n/permissions.p7s" "$out/$n/"
    sed '\:<topic_expression>pmu/command</topic_expression>:,\:</topic_rule>: s:<enable_write_access_control>true<:<enable_write_access_control>false<:' \
      "$pki/governance.xml" > "$out/governance.xml"
    [ "$(grep -c '<enable_write_access_control>false<' "$out/governance.xml")" -eq 1 ] ||
      die "could not relax the governance"
    openssl smime -sign -text -nodetach -in "$out/governance.xml" -out "$out/governance.p7s" \
      -signer "$pki/permissions_ca.pem" -inkey "$pki/ca/permissions_ca.key"
    ;;
  single-ca)
    w="$out/world" i="$out/intruder"
    mkdir -p "$w" "$i/mission-computer" "$out/ca"
    cat > "$out/ca/openssl.cnf" <<CNF
[ req ]
distinguished_name = dn
prompt = no
[ dn ]
O = pmu-dds
[ ca_cert ]
basicConstraints = critical, CA:TRUE
keyUsage = critical, keyCertSign, cRLSign, digitalSignature
[ identity_cert ]
basicConstraints = critical, CA:FALSE
keyUsage = critical, digitalSignature, keyAgreement
CNF
    cnf="$out/ca/openssl.cnf"
    openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$out/ca/ca.key" 2>/dev/null
    openssl req -config "$cnf" -new -x509 -sha256 -days 30 -key "$out/ca/ca.key" -subj "/O=pmu-dds/CN=pmu-dds Single CA" \
      -extensions ca_cert -out "$w/identity_ca.pem"
    cp "$w/identity_ca.pem" "$w/permissions_ca.pem"
    serial=100
    for n in pmu-service ground-station mission-computer; do
      mkdir -p "$w/$n"
      openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$w/$n/key.pem" 2>/dev/null
      openssl req -config "$cnf" -new -sha256 -key "$w/$n/key.pem" -subj "/O=pmu-dds/CN=$n" -out "$out/ca/$n.csr"
      serial=$((serial + 1))
      openssl x509 -req -in "$out/ca/$n.csr" -CA "$w/identity_ca.pem" -CAkey "$out/ca/ca.key" -set_serial $serial \
        -days 30 -sha256 -extfile "$cnf" -extensions identity_cert -out "$w/$n/cert.pem" 2>/dev/null
      [ $n = mission-computer ] ||
        openssl smime -sign -text -nodetach -in "$pki/$n/permissions.xml" -out "$w/$n/permissions.p7s" \
          -signer "$w/identity_ca.pem" -inkey "$out/ca/ca.key"
    done
    openssl smime -sign -text -nodetach -in "$pki/governance.xml" -out "$w/governance.p7s" \
      -signer "$w/identity_ca.pem" -inkey "$out/ca/ca.key"
    n=mission-computer
    cp "$w/identity_ca.pem" "$w/permissions_ca.pem" "$i/"
    mv "$w/$n/cert.pem" "$w/$n/key.pem" "$i/$n/"
    sed -e "s:CN=ground-station,O=pmu-dds:CN=$n,O=pmu-dds:" "$pki/ground-station/permissions.xml" > "$i/$n/permissions.xml"
    for doc in "$i/$n/permissions" "$i/governance"; do
      [ -f "$doc.xml" ] || cp "$pki/governance.xml" "$doc.xml"
      openssl smime -sign -text -nodetach -in "$doc.xml" -out "$doc.p7s" -signer "$i/$n/cert.pem" -inkey "$i/$n/key.pem"
    done
    ;;
  window)
    [ $# -eq 5 ] || die "window needs START and END"
    n=ground-station
    mkdir -p "$out/$n"
    cp "$pki/identity_ca.pem" "$pki/permissions_ca.pem" "$pki/governance.p7s" "$out/"
    cp "$pki/$n/permissions.p7s" "$out/$n/"
    openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$out/$n/key.pem" 2>/dev/null
    openssl req -config "$pki/ca/openssl.cnf" -new -sha256 -key "$out/$n/key.pem" -subj "/O=pmu-dds/CN=$n" \
      -out "$out/$n/req.csr"
    openssl ca -config "$pki/ca/openssl.cnf" -name identity_ca -batch -notext -startdate "$4" -enddate "$5" \
      -in "$out/$n/req.csr" -out "$out/$n/cert.pem" 2>/dev/null || die "openssl ca refused $4..$5"
    rm -f "$out/$n/req.csr"
    ;;
  *) die "unknown variant '$kind'" ;;
esac
