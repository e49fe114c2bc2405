"""A camera as the frame store's tests drive it: the capture's output protocol (hdl/capture.py's strobes and
latencies), frame by frame, with the faults a malformed stream has."""


class Camera:
    """The capture's output protocol (hdl/capture.py's latencies): frame_start, then per row row_start, two clocks,
    one pixel write per ``gap`` clocks, row_end a clock after the last write; frame_done with frame_ok."""

    def __init__(self, ctx, feed, domain):
        self.ctx, self.w, self.domain = ctx, feed, domain

    async def pulse(self, signal, value=1, clocks=1):
        self.ctx.set(signal, value)
        await self.ctx.tick(self.domain).repeat(clocks)
        self.ctx.set(signal, 0)

    async def frame(self, image, *, ok=True, done=True, gap=1):
        status = self.w.status
        await self.pulse(status.frame_start)
        await self.ctx.tick(self.domain).repeat(3)
        for row in image:
            await self.pulse(status.row_start)
            await self.ctx.tick(self.domain)
            for value in row:
                self.ctx.set(self.w.write.data, int(value))
                await self.pulse(self.w.write.en)
                if gap > 1:
                    await self.ctx.tick(self.domain).repeat(gap - 1)
            await self.pulse(status.row_end)
            await self.ctx.tick(self.domain).repeat(6)
        if done:
            self.ctx.set(status.frame_ok, int(ok))
            await self.pulse(status.frame_done)
            self.ctx.set(status.frame_ok, 0)
        await self.ctx.tick(self.domain).repeat(4)
