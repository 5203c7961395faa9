#pragma once
// The Cyclone configuration of the tests' observing participants: loopback only, no multicast,
// 127.0.0.1 as unicast peer. Written out here, not made by dds::discoveryConfigXml, so that the
// observer stays independent of the code under test.

namespace dds_test {

inline constexpr const char* kLoopbackObserverConfig =
    "<CycloneDDS><Domain><General><Interfaces><NetworkInterface address=\"127.0.0.1\"/>"
    "</Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery>"
    "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>"
    "</Discovery></Domain></CycloneDDS>";

}  // namespace dds_test
