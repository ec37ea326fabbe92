"""An independent OPC UA client (the Python `asyncua` package) against `cnc-opcua`.

Run by the Rust test `opcua_python` beside a real-time `cnc run --opcua`: it browses the
tree, reads an axis position a few times with the source timestamps, subscribes to the
machine's tick, writes anonymously (refused) and as a logged-in user over Basic256Sha256
SignAndEncrypt (allowed), and prints what it saw as one JSON object for the test to judge.

usage: asyncua_client.py URL AXIS_PATH WRITE_PATH USER PASSWORD WORK_DIR
"""

import asyncio
import json
import sys
from pathlib import Path

from asyncua import Client, ua
from asyncua.crypto.cert_gen import setup_self_signed_certificate
from asyncua.crypto.security_policies import SecurityPolicyBasic256Sha256
from cryptography.x509.oid import ExtendedKeyUsageOID

NAMESPACE = "urn:cnc-plc-runtime:hli"
SAMPLING_MS = 50
SUBSCRIBED_S = 2.0


class Changes:
    """Counts the data changes of a subscription; `first` is set at the first."""

    def __init__(self):
        self.count = 0
        self.first = asyncio.Event()

    def datachange_notification(self, node, value, data):
        self.count += 1
        self.first.set()


def unix_ns(stamp):
    return int(stamp.timestamp() * 1e9)


async def anonymous_part(url, axis_path, write_path, out):
    async with Client(url=url) as client:
        ns = await client.get_namespace_index(NAMESPACE)
        # The tree: Objects/HLI/gpAx/[6]/lr_state holds the axis's leaves.
        hli = await client.nodes.objects.get_child([f"{ns}:HLI"])
        axes = await hli.get_child([f"{ns}:gpAx"])
        index = axis_path.split("[")[1].split("]")[0]
        state = await axes.get_child([f"{ns}:[{index}]", f"{ns}:lr_state"])
        out["browsed"] = sorted([(await c.read_browse_name()).Name for c in await state.get_children()])
        header = lambda leaf: client.get_node(ua.NodeId(f"header.{leaf}", ns))
        out["cycle_ns"] = await header("cnc_cycle_ns").read_value()
        position = client.get_node(ua.NodeId(axis_path, ns))
        reads = []
        for _ in range(6):
            value = await position.read_data_value()
            reads.append([value.Value.Value, unix_ns(value.SourceTimestamp)])
            await asyncio.sleep(0.2)
        out["reads"] = reads
        scaled = await client.get_node(ua.NodeId(axis_path + "_scaled", ns)).read_value()
        out["scaled"] = scaled

        changes = Changes()
        subscription = await client.create_subscription(SAMPLING_MS, changes)
        tick = client.get_node(ua.NodeId("Machine.Tick", ns))
        await subscription.subscribe_data_change(tick, queuesize=100, sampling_interval=SAMPLING_MS)
        # Counted from the first change on, for SUBSCRIBED_S: every sample of the tick is a
        # change (it moves every millisecond).
        await asyncio.wait_for(changes.first.wait(), 10)
        changes.count = 0
        await asyncio.sleep(SUBSCRIBED_S)
        out["changes"] = changes.count
        await subscription.delete()
        out["expected_changes"] = int(SUBSCRIBED_S * 1000 / SAMPLING_MS)

        try:
            await client.get_node(ua.NodeId(write_path, ns)).write_value(ua.Variant(123, ua.VariantType.UInt32))
            out["anonymous_write"] = "Good"
        except ua.UaStatusCodeError as e:
            out["anonymous_write"] = type(e).__name__


async def user_part(url, write_path, user, password, work, out):
    work = Path(work)
    cert, key = work / "client-cert.der", work / "client-key.pem"
    await setup_self_signed_certificate(
        key, cert, "urn:cnc-opcua-asyncua-test", "localhost",
        [ExtendedKeyUsageOID.CLIENT_AUTH], {"countryName": "DE", "organizationName": "cnc", "commonName": "asyncua test"},
    )
    client = Client(url=url)
    client.application_uri = "urn:cnc-opcua-asyncua-test"
    await client.set_security(SecurityPolicyBasic256Sha256, certificate=str(cert), private_key=str(key),
                              mode=ua.MessageSecurityMode.SignAndEncrypt)
    client.set_user(user)
    client.set_password(password)
    async with client:
        ns = await client.get_namespace_index(NAMESPACE)
        node = client.get_node(ua.NodeId(write_path, ns))
        try:
            await node.write_value(ua.Variant(123, ua.VariantType.UInt32))
            out["user_write"] = "Good"
        except ua.UaStatusCodeError as e:
            out["user_write"] = type(e).__name__
        out["read_back"] = await node.read_value()


async def main():
    url, axis_path, write_path, user, password, work = sys.argv[1:7]
    out = {}
    await anonymous_part(url, axis_path, write_path, out)
    await user_part(url, write_path, user, password, work, out)
    print(json.dumps(out))


if __name__ == "__main__":
    asyncio.run(main())
