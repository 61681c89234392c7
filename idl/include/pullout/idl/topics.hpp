// The names on the wire: DDS topic names (DESIGN.md, topics table) and the Fast DDS XML profile
// names of their endpoints (config/dds/*.xml). Shared by both DDS edges.
#pragma once

namespace pullout::idl {

inline constexpr const char* kRequestTopic = "pullout/request";
inline constexpr const char* kPathTopic = "pullout/path";
inline constexpr const char* kStatusTopic = "pullout/status";
inline constexpr const char* kProgressTopic = "pullout/progress";

inline constexpr const char* kParticipantProfile = "pullout_participant";
inline constexpr const char* kRequestWriterProfile = "pullout_request_writer";
inline constexpr const char* kRequestReaderProfile = "pullout_request_reader";
inline constexpr const char* kPathWriterProfile = "pullout_path_writer";
inline constexpr const char* kPathReaderProfile = "pullout_path_reader";
inline constexpr const char* kStatusWriterProfile = "pullout_status_writer";
inline constexpr const char* kStatusReaderProfile = "pullout_status_reader";
inline constexpr const char* kProgressWriterProfile = "pullout_progress_writer";
inline constexpr const char* kProgressReaderProfile = "pullout_progress_reader";

}  // namespace pullout::idl
