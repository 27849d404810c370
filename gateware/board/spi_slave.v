// SPI slave of the datapath register map (docs/protocol.md, "Datapath register
// map"; the master is firmware/ports/rp2040_ice40/spi_regmap.c).
//
// Transaction, SPI mode 0 (SCK idles low, both sides sample on the rising
// edge), bytes MSB first:
//   CS low; command byte (0x80 read, 0x00 write, anything else: the rest of
//   the transaction is ignored and MISO stays 0); word address, 16 bits
//   big-endian; then
//   write: 4 data bytes little-endian; the register write happens once the
//          4th is complete (a transaction cut short by CS high writes
//          nothing; bytes beyond the 7th are ignored);
//   read:  one turnaround byte, then the slave answers in the next 4 byte
//          slots (LSB byte first, each byte MSB first). MISO is 0 elsewhere.
//   CS high at any point resets the transaction.
//
// The slave runs in the system clock domain and oversamples: SCK, CS_n and
// MOSI each pass a two-flop synchroniser. LIMITS: SCK's high and low phases
// must each last at least 4 clk periods (SCK <= clk / 8: 1.5 MHz at 12 MHz);
// CS_n must fall at least 2 clk periods before the first rising SCK edge and
// stay high for at least 4 clk periods between transactions (a shorter high
// pulse may be missed, and the next transaction then counts as bytes 8+ of
// this one and is ignored).
// MISO changes 2-3 clk after a rising SCK edge (once the
// master has sampled), not on the falling edge: a falling edge is seen up to
// 3 clk late, which with a 4-clk low phase would leave no setup margin, while
// after the rising edge MISO has the whole rest of the period (>= 4 clk).
//
// Register-side handshake: rd_en pulses for one clk when a read's address is
// complete; rd_data must then be valid and stable by the end of the turnaround
// byte (>= 64 clk later), where it is loaded into the MISO shift register.
// wr_en pulses for one clk with wr_addr/wr_data valid.
`default_nettype none

/* verilator lint_off DECLFILENAME */ // file name is fixed by the project layout
module cbvh_spi_slave (
    input  wire        clk,
    input  wire        rst,       // synchronous, active high
    input  wire        sck,
    input  wire        cs_n,
    input  wire        mosi,
    output wire        miso,
    output reg         rd_en,
    output wire [15:0] rd_addr,   // word address (byte address / 4)
    input  wire [31:0] rd_data,
    output reg         wr_en,
    output wire [15:0] wr_addr,   // word address
    output reg  [31:0] wr_data
);
/* verilator lint_on DECLFILENAME */

    localparam [7:0] CMD_READ = 8'h80, CMD_WRITE = 8'h00;

    // two-flop synchronisers, plus the previous synchronised SCK for edges
    reg [1:0] sck_q, cs_q, mosi_q;
    reg       sck_d;
    always @(posedge clk) begin
        if (rst) begin
            sck_q  <= 2'b00;
            cs_q   <= 2'b11;
            mosi_q <= 2'b00;
            sck_d  <= 1'b0;
        end else begin
            sck_q  <= {sck_q[0], sck};
            cs_q   <= {cs_q[0], cs_n};
            mosi_q <= {mosi_q[0], mosi};
            sck_d  <= sck_q[1];
        end
    end
    wire sck_s  = sck_q[1];
    wire cs_s   = cs_q[1];
    wire mosi_s = mosi_q[1];
    // MOSI went through the same synchroniser, so its sample taken together
    // with the first high SCK sample lies inside the stable window around the
    // rising edge (the master changes MOSI only on falling edges)
    wire rise   = sck_s & ~sck_d & ~cs_s;

    reg  [2:0]  bitcnt;     // bits of the current byte received
    reg  [2:0]  bytecnt;    // complete bytes; 7 = the transaction is over
    reg  [6:0]  sr;         // bits of the current byte so far
    reg         is_rd, is_wr;
    reg  [15:0] addr;
    reg  [31:0] tx;         // read data in wire order: shifted out from bit 31
    wire [7:0]  byte_in = {sr, mosi_s};

    assign rd_addr = addr;
    assign wr_addr = addr;
    assign miso    = tx[31];  // tx is 0 outside a read's data slots

    always @(posedge clk) begin
        rd_en <= 1'b0;
        wr_en <= 1'b0;
        if (rst || cs_s) begin
            bitcnt  <= 3'd0;
            bytecnt <= 3'd0;
            is_rd   <= 1'b0;
            is_wr   <= 1'b0;
            tx      <= 32'd0;
        end else if (rise) begin
            sr     <= byte_in[6:0];
            bitcnt <= bitcnt + 3'd1;
            // a read's data bits: the next bit for the master's next edge
            tx     <= {tx[30:0], 1'b0};
            if (bitcnt == 3'd7 && bytecnt != 3'd7) begin
                bytecnt <= bytecnt + 3'd1;
                case (bytecnt)
                    3'd0: begin
                        is_rd <= (byte_in == CMD_READ);
                        is_wr <= (byte_in == CMD_WRITE);
                    end
                    3'd1: addr[15:8] <= byte_in;
                    3'd2: begin
                        addr[7:0] <= byte_in;
                        rd_en     <= is_rd;
                    end
                    3'd3: begin
                        // end of the turnaround byte: the data go out LSB
                        // byte first, each byte MSB first
                        if (is_rd)
                            tx <= {rd_data[7:0], rd_data[15:8], rd_data[23:16], rd_data[31:24]};
                        wr_data[7:0] <= byte_in;
                    end
                    3'd4: wr_data[15:8]  <= byte_in;
                    3'd5: wr_data[23:16] <= byte_in;
                    default: begin    // 3'd6: the 4th data byte
                        wr_data[31:24] <= byte_in;
                        wr_en          <= is_wr;
                    end
                endcase
            end
        end
    end
endmodule

`default_nettype wire
