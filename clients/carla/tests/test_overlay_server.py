"""The CARLA overlay through the real server ($DOWNPOUR_SERVER), with real pictures: the server's
own dry COCKPIT frame and its depth stand for what CARLA's RGB and depth cameras give (as CARLA's
raw BGRA and its 24-bit depth encoding). The stand-in world ticks, the overlay sends each tick's
pair with the Step, and the frames that come back are the picture under rain and a wet windshield,
with their ground truth: the clean frame is the picture, and the cabin in the picture (nearer than
the glass by its depth) keeps the water off."""

import io
import math
import os
import sys
import unittest

import downpour_client
from downpour.v1 import downpour_pb2 as pb

from downpour_carla.bridge import CarlaBridge, CarlaOverlay

from .standin import Vehicle, World

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tests", "python"))
from server_process import SERVER, ServerProcess  # noqa: E402

W, H, FOV = 320, 180, 60.0
CARLA_DEPTH_FULL = 2 ** 24 - 1  # CARLA's depth: (R + 256 G + 65536 B) / (2^24 - 1) of 1000 m


def carla_depth_bgra(depth_cm):
    """Centimetres (0 = the sky) as CARLA's depth camera's raw BGRA."""
    out = bytearray()
    for cm in depth_cm:
        v = CARLA_DEPTH_FULL if cm == 0 else round(cm / 100_000 * CARLA_DEPTH_FULL)
        out += bytes([(v >> 16) & 0xff, (v >> 8) & 0xff, v & 0xff, 255])
    return bytes(out)


def psnr(a, b, mask=None):
    from PIL import ImageChops, ImageStat
    rms = ImageStat.Stat(ImageChops.difference(a, b), mask=mask).rms
    mse = sum(r * r for r in rms) / 3
    return float("inf") if mse == 0 else 10 * math.log10(255 * 255 / mse)


def setUpModule():
    if not SERVER:
        raise unittest.SkipTest("DOWNPOUR_SERVER is not set")


class OverlayThroughTheServerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = ServerProcess()
        cls.server.wait_started()

    @classmethod
    def tearDownClass(cls):
        cls.server.stop()

    def test_carlas_pictures_come_back_under_the_rain(self):
        from PIL import Image
        with downpour_client.DownpourClient(self.server.target) as client:
            # The "CARLA" pictures: the server's own COCKPIT frame of a dry day, and its depth.
            dry = pb.Update(sim_time_s=0.0)
            dry.vehicle.position_m.y = -5.25
            dry.weather.cloudiness, dry.weather.sun_altitude_deg = 0.3, 35.0
            source = client.create_session(
                [downpour_client.view_spec("COCKPIT", W, H, fov_deg=FOV, outputs="depth")],
                initial=dry)
            shot = client.step(source.session_id, 0.05, dry)[0]
            client.close_session(source.session_id)
            picture = Image.open(io.BytesIO(shot.jpeg)).convert("RGB")
            depth_cm = list(Image.open(io.BytesIO(shot.depth_png)).getdata())
            self.assertEqual(len(depth_cm), W * H)

            ego = Vehicle(7, (10.0, 5.0, 0.0), 0.0)
            with open(os.path.join(REPO, "tests", "data", "maps", "sumo_grid.xodr")) as file:
                xodr = file.read()
            world = World([ego], xodr=xodr,
                          pictures={"rgb": picture.convert("RGBA").tobytes("raw", "BGRA"),
                                    "depth": carla_depth_bgra(depth_cm)})
            bridge = CarlaBridge(world, ego)
            overlay = CarlaOverlay(world, ego, bridge, lambda loc, rot: (loc, rot), width=W,
                                   height=H, quality=95)
            spec = overlay.view_spec(fov_deg=FOV)
            spec.outputs.extend([pb.OUTPUT_CLEAN, pb.OUTPUT_WATER_MASK])
            info = bridge.create_session(client, [spec])
            frames = []
            try:
                bridge.run_lockstep(client, info.session_id, 1.5, dt_s=0.05, overlay=overlay,
                                    on_step=lambda update, got: frames.extend(got))
            finally:
                client.close_session(info.session_id)
                overlay.destroy()

        self.assertEqual(len(frames), 30)
        self.assertTrue(all(f.stats.background_repeats == 0 for f in frames), "a picture a tick")
        self.assertTrue(all(f.stats.rain_streaks > 0 for f in frames))
        last = frames[-1]
        self.assertGreater(last.stats.drops_on_glass, 0)
        rainy = Image.open(io.BytesIO(last.jpeg)).convert("RGB")
        clean = Image.open(io.BytesIO(last.clean_jpeg)).convert("RGB")
        mask = Image.open(io.BytesIO(last.water_mask_png))
        look = os.environ.get("DOWNPOUR_LOOK_DIR")  # to look at: the picture and what came back
        if look:
            for name, image in (("picture", picture), ("rainy", rainy), ("clean", clean),
                                ("mask", mask.point(lambda m: min(255, 4 * m)))):
                image.save(os.path.join(look, f"carla_overlay_{name}.png"))
        self.assertEqual((rainy.size, clean.size, mask.size, mask.mode),
                         ((W, H), (W, H), (W, H), "L"))
        # The clean frame is CARLA's picture (JPEG'd three times: the server's, the overlay's and
        # the frame's).
        clean_psnr = psnr(clean, picture)
        # The cabin in the picture (nearer than a metre) gets no water; the glass does.
        cabin = Image.new("L", (W, H))
        cabin.putdata([255 if 0 < cm < 100 else 0 for cm in depth_cm])
        outside = Image.new("L", (W, H))
        outside.putdata([255 if cm == 0 or cm >= 100 else 0 for cm in depth_cm])
        masked = list(mask.getdata())
        cabin_pixels = [m for m, cm in zip(masked, depth_cm) if 0 < cm < 100]
        outside_pixels = [m for m, cm in zip(masked, depth_cm) if cm == 0 or cm >= 100]
        cabin_wet = sum(m > 8 for m in cabin_pixels) / len(cabin_pixels)
        outside_wet = sum(m > 8 for m in outside_pixels) / len(outside_pixels)
        print(f"\nclean frame against the picture: {clean_psnr:.1f} dB; the water changed "
              f"{100 * outside_wet:.1f}% of the pixels outside the cabin by 8 levels or more, "
              f"{100 * cabin_wet:.2f}% of the cabin's ({len(cabin_pixels)} pixels); rainy against "
              f"the picture: {psnr(rainy, picture, outside):.1f} dB outside, "
              f"{psnr(rainy, picture, cabin):.1f} dB over the cabin")
        self.assertGreater(clean_psnr, 30.0)
        self.assertGreater(len(cabin_pixels), W * H // 10)
        self.assertGreater(outside_wet, 0.02)
        self.assertLess(cabin_wet, 0.02)


if __name__ == "__main__":
    unittest.main()
