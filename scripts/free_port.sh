# free_port: prints a TCP port on 127.0.0.1 that nothing listens on, for a ROS master of a script's
# own (the rostests and the other checks start masters of their own meanwhile). Source it.
# The port lies below the kernel's ephemeral range: every node's XML-RPC server, every rostest's
# master and every outgoing connection takes a port from that range, so a port picked inside it
# can be taken between the pick and roscore's bind ("port ... is already in use").
free_port() {
  local low=32768 port
  read -r low _ < /proc/sys/net/ipv4/ip_local_port_range 2>/dev/null || true
  [ "$low" -gt 21000 ] || low=32768
  while true; do
    port=$((20000 + RANDOM % (low - 20000)))
    (exec 3<>"/dev/tcp/127.0.0.1/$port") 2>/dev/null || { echo "$port"; return; }
  done
}
