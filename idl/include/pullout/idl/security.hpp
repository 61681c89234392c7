// DDS Security for pullout participants: Fast DDS's builtin plugins (PKI-DH authentication,
// Access-Permissions access control, AES-GCM-GMAC cryptography; OMG DDS Security 1.1).
//
// A participant's credentials are one directory with five files (scripts/make-test-pki makes such
// directories for tests; a deployment makes its own with its own CA):
//
//   ca.pem           the CA that issued every participant's identity and signed the documents
//   cert.pem         this participant's identity certificate (X.509, PEM)
//   key.pem          its private key (PEM)
//   governance.p7s   the domain's governance document, signed by the CA
//   permissions.p7s  this participant's permissions document, signed by the CA
//
// In a secure deployment every vehicle's endpoints live in the DDS partition named after its
// vehicle id, and its permissions allow it only that partition (config/dds/security/): the
// service writes each vehicle's path and status through writers in that vehicle's partition, and
// accepts a request or progress sample only from a writer in the partition of the sample's
// vehicle id. So an authenticated vehicle can neither read, approve nor replace another's path.
#pragma once

#include <string>

namespace eprosima::fastdds::dds {
class DomainParticipantQos;
}  // namespace eprosima::fastdds::dds

namespace pullout::idl {

// The file names expected in a credentials directory, in the order above.
inline constexpr const char* kSecurityFiles[] = {"ca.pem", "cert.pem", "key.pem", "governance.p7s", "permissions.p7s"};

// Adds the dds.sec.* properties that enable the three plugins with the credentials in `dir` to
// `qos`. Throws std::invalid_argument naming the first missing or unreadable file. Fast DDS
// checks the files' contents only when the participant is created (an invalid certificate or
// document then fails the creation, with the reason in Fast DDS's log, category SECURITY).
void add_security_properties(const std::string& dir, eprosima::fastdds::dds::DomainParticipantQos& qos);

// Whether `vehicle_id` can be used as a partition name as is: partition names are fnmatch
// patterns in DDS, so an id with one of * ? [ ] \ would match other vehicles' partitions.
bool is_literal_partition_name(const std::string& vehicle_id);

}  // namespace pullout::idl
